#include "sadsplat/gaussians/densification_stats.h"

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAGuard.h>
#endif

#include <string>

#include "sadsplat/common/cuda_support.h"
#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {
#if SADSPLAT_HAVE_CUDA
namespace densification_stats {
void accumulateCuda(const at::Tensor& grad, const at::Tensor& radii, float scale_x, float scale_y,
                    at::Tensor& grad_accum, at::Tensor& denom, at::Tensor& max_radii, void* stream);
}  // namespace densification_stats
#endif

namespace {

void expectStatistic(const at::Tensor& t, const char* name, std::int64_t n,
                     const at::Tensor& grad) {
  if (!t.defined() || t.dim() != 1 || t.size(0) != n || t.scalar_type() != at::kFloat ||
      t.device() != grad.device() || !t.is_contiguous()) {
    throw Error("<densification statistics>", name,
                "a contiguous float32 [" + std::to_string(n) + "] tensor on the gradient's device",
                "another shape, type, device or layout");
  }
}

}  // namespace

void accumulateScreenGradientsReference(const at::Tensor& means2d_grad, const at::Tensor& radii,
                                        double scale_x, double scale_y, at::Tensor& grad_accum,
                                        at::Tensor& denom, at::Tensor& max_radii) {
  const at::Tensor gx = means2d_grad.select(1, 0) * scale_x;
  const at::Tensor gy = means2d_grad.select(1, 1) * scale_y;
  const at::Tensor norm = at::sqrt(gx * gx + gy * gy);
  const at::Tensor visible = radii > 0;
  grad_accum += at::where(visible, norm, at::zeros_like(norm));
  denom += visible.to(denom.scalar_type());
  max_radii.copy_(
      at::where(visible, at::max(max_radii, radii.to(max_radii.scalar_type())), max_radii));
}

void accumulateScreenGradients(const at::Tensor& means2d_grad, const at::Tensor& radii,
                               double scale_x, double scale_y, at::Tensor& grad_accum,
                               at::Tensor& denom, at::Tensor& max_radii) {
  const std::int64_t n = means2d_grad.size(0);
  if (means2d_grad.dim() != 2 || means2d_grad.size(1) != 2 || radii.dim() != 1 ||
      radii.size(0) != n || radii.device() != means2d_grad.device()) {
    throw Error("<densification statistics>", "means2d gradient / radii",
                "[N, 2] and [N] on one device",
                "means2d " + std::to_string(means2d_grad.dim()) + "-d, radii " +
                    std::to_string(radii.dim()) + "-d");
  }
  expectStatistic(grad_accum, "grad_accum", n, means2d_grad);
  expectStatistic(denom, "denom", n, means2d_grad);
  expectStatistic(max_radii, "max_radii", n, means2d_grad);
#if SADSPLAT_HAVE_CUDA
  if (means2d_grad.is_cuda() && means2d_grad.scalar_type() == at::kFloat &&
      radii.scalar_type() == at::kInt) {
    const c10::cuda::CUDAGuard guard(means2d_grad.device());
    const at::Tensor g = means2d_grad.contiguous(), r = radii.contiguous();
    densification_stats::accumulateCuda(g, r, static_cast<float>(scale_x),
                                        static_cast<float>(scale_y), grad_accum, denom, max_radii,
                                        currentStream(g));
    return;
  }
#endif
  accumulateScreenGradientsReference(means2d_grad, radii, scale_x, scale_y, grad_accum, denom,
                                     max_radii);
}

}  // namespace gaussians
}  // namespace sadsplat
