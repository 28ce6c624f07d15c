#include "sadsplat/semantic_drop/l0_force.h"

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAGuard.h>
#endif

#include <string>

#include "sadsplat/common/cuda_support.h"
#include "sadsplat/common/error.h"

namespace sadsplat {
namespace semantic_drop {

#if SADSPLAT_HAVE_CUDA
namespace l0_force {
void addCuda(float* grad, const float* direction, const float* opacity_grad, const float* weights,
             std::int64_t n, float strength, double* sums, void* stream);
}  // namespace l0_force
#endif

namespace {

void expectRow(const at::Tensor& t, const char* name, const at::Tensor& grad) {
  if (!t.defined() || t.dim() != 1 || t.size(0) != grad.size(0) || t.device() != grad.device()) {
    throw Error("<L0 force>", name,
                "a [" + std::to_string(grad.size(0)) + "] tensor on the gradient's device",
                t.defined() ? std::to_string(t.dim()) + "-d on " + t.device().str()
                            : std::string("undefined"));
  }
}

}  // namespace

void addBalancedL0ForceReference(at::Tensor& grad, const at::Tensor& direction,
                                 const at::Tensor& opacity_grad, const at::Tensor& weights,
                                 double strength) {
  const at::Tensor reached = (opacity_grad != 0).to(grad.dtype());
  const at::Tensor rgb_force = (grad.abs() * reached).sum();
  const at::Tensor l0_force = (direction * reached).sum();
  // Both sums are over the same gates, so their ratio is the ratio of the means.
  const at::Tensor scale =
      at::where(l0_force > 0, rgb_force / l0_force.clamp_min(1e-30), at::zeros_like(l0_force));
  at::Tensor force = direction * reached * (strength * scale);
  if (weights.defined()) force = force * weights;
  grad.add_(force);
}

void addBalancedL0Force(at::Tensor& grad, const at::Tensor& direction,
                        const at::Tensor& opacity_grad, const at::Tensor& weights,
                        double strength) {
  if (!grad.defined() || grad.dim() != 1) {
    throw Error("<L0 force>", "grad", "a [N] tensor",
                grad.defined() ? std::to_string(grad.dim()) + "-d" : std::string("undefined"));
  }
  expectRow(direction, "direction", grad);
  expectRow(opacity_grad, "opacity_grad", grad);
  if (weights.defined()) expectRow(weights, "weights", grad);
#if SADSPLAT_HAVE_CUDA
  const auto is_float = [](const at::Tensor& t) {
    return !t.defined() || t.scalar_type() == at::kFloat;
  };
  if (grad.is_cuda() && grad.is_contiguous() && is_float(grad) && is_float(direction) &&
      is_float(opacity_grad) && is_float(weights)) {
    const c10::cuda::CUDAGuard guard(grad.device());
    const at::Tensor d = direction.contiguous(), o = opacity_grad.contiguous();
    const at::Tensor w = weights.defined() ? weights.contiguous() : at::Tensor();
    at::Tensor sums = at::empty({2}, grad.options().dtype(at::kDouble));
    l0_force::addCuda(grad.data_ptr<float>(), d.data_ptr<float>(), o.data_ptr<float>(),
                      w.defined() ? w.data_ptr<float>() : nullptr, grad.size(0),
                      static_cast<float>(strength), sums.data_ptr<double>(), currentStream(grad));
    return;
  }
#endif
  addBalancedL0ForceReference(grad, direction, opacity_grad, weights, strength);
}

}  // namespace semantic_drop
}  // namespace sadsplat
