#include "sadsplat/semantic_drop/hard_concrete.h"

#include <torch/csrc/autograd/custom_function.h>

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAGuard.h>
#include "sadsplat/common/cuda_support.h"
#endif

#include <algorithm>
#include <cmath>

#include "hard_concrete_backend.h"
#include "sadsplat/gaussians/counter_random.h"

namespace sadsplat {
namespace semantic_drop {
namespace {

#if SADSPLAT_HAVE_CUDA
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

hard_concrete_fused::GateParams gateParams(const AutogradContext* ctx) {
  hard_concrete_fused::GateParams p;
  p.key.low = static_cast<std::uint32_t>(ctx->saved_data.at("key_low").toInt());
  p.key.high = static_cast<std::uint32_t>(ctx->saved_data.at("key_high").toInt());
  p.inv_beta = static_cast<float>(ctx->saved_data.at("inv_beta").toDouble());
  p.l = static_cast<float>(ctx->saved_data.at("l").toDouble());
  p.r = static_cast<float>(ctx->saved_data.at("r").toDouble());
  p.closed_gradient = ctx->saved_data.at("closed_gradient").toBool();
  return p;
}

// The gate of a contiguous float32 CUDA log_alpha; its gradient recomputed from log_alpha.
class FusedCounterGate : public torch::autograd::Function<FusedCounterGate> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& log_alpha,
                            gaussians::CounterKey key, const HardConcreteParams& p,
                            bool closed_gradient) {
    const c10::cuda::CUDAGuard guard(log_alpha.device());
    const at::Tensor a = log_alpha.contiguous();
    ctx->saved_data["key_low"] = static_cast<std::int64_t>(key.low);
    ctx->saved_data["key_high"] = static_cast<std::int64_t>(key.high);
    ctx->saved_data["inv_beta"] = 1.0 / p.beta;
    ctx->saved_data["l"] = p.l;
    ctx->saved_data["r"] = p.r;
    ctx->saved_data["closed_gradient"] = closed_gradient;
    ctx->save_for_backward({a});
    at::Tensor gate = at::empty_like(a);
    hard_concrete_fused::forwardCuda(a.data_ptr<float>(), a.numel(), gateParams(ctx),
                                     gate.data_ptr<float>(), currentStream(a));
    return gate;
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const at::Tensor a = ctx->get_saved_variables()[0];
    const c10::cuda::CUDAGuard guard(a.device());
    const at::Tensor g = grads[0].to(at::kFloat).contiguous();
    at::Tensor grad = at::empty_like(a);
    hard_concrete_fused::backwardCuda(a.data_ptr<float>(), g.data_ptr<float>(), a.numel(),
                                      gateParams(ctx), grad.data_ptr<float>(), currentStream(a));
    return {grad, at::Tensor(), at::Tensor(), at::Tensor()};
  }
};
#endif

using filters::logitOfThreshold;

}  // namespace

at::Tensor probabilityNonZero(const at::Tensor& log_alpha, const HardConcreteParams& p) {
  return at::sigmoid(log_alpha - p.beta * logitOfThreshold(p));
}

at::Tensor sampleGate(const at::Tensor& log_alpha, const at::Tensor& uniform,
                      const HardConcreteParams& p, bool closed_gradient) {
  const at::Tensor u = uniform.clamp(1e-6, 1 - 1e-6);
  const at::Tensor s = at::sigmoid((at::log(u) - at::log(1 - u) + log_alpha) / p.beta);
  const at::Tensor stretched = s * (p.r - p.l) + p.l;
  if (!closed_gradient) return stretched.clamp(0, 1);
  // The value of clamp(0, 1), the gradient of clamp_max(1): it passes below 0.
  const at::Tensor open_above = stretched.clamp_max(1);
  return open_above + (open_above.clamp_min(0) - open_above).detach();
}

bool counterGateIsFused(const at::Tensor& log_alpha) {
#if SADSPLAT_HAVE_CUDA
  return log_alpha.is_cuda() && log_alpha.scalar_type() == at::kFloat;
#else
  (void)log_alpha;
  return false;
#endif
}

at::Tensor sampleCounterGate(const at::Tensor& log_alpha, std::uint64_t seed, std::uint64_t purpose,
                             std::uint64_t iteration, const HardConcreteParams& p,
                             bool closed_gradient) {
#if SADSPLAT_HAVE_CUDA
  if (counterGateIsFused(log_alpha)) {
    return FusedCounterGate::apply(log_alpha, gaussians::counterKey(seed, purpose, iteration), p,
                                   closed_gradient);
  }
#endif
  const at::Tensor u =
      gaussians::counterUniform(log_alpha.numel(), seed, purpose, iteration, log_alpha.options())
          .view(log_alpha.sizes());
  return sampleGate(log_alpha, u, p, closed_gradient);
}

at::Tensor deterministicGate(const at::Tensor& log_alpha, const HardConcreteParams& p) {
  return (at::sigmoid(log_alpha) * (p.r - p.l) + p.l).clamp(0, 1);
}

}  // namespace semantic_drop
}  // namespace sadsplat
