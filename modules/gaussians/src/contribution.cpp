#include "sadsplat/gaussians/contribution.h"

#include <c10/core/GradMode.h>

#include <string>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {

at::Tensor blendingWeightSums(const GaussianParams& gaussians,
                              const std::vector<RasterCamera>& cameras) {
  c10::AutoGradMode grad_mode(true);
  // A one-channel feature of 1 per Gaussian composites to F(pixel) = sum_i 1 * alpha_i T_i, so
  // dF/d(feature_i) = alpha_i T_i, summed over the pixels by the backward pass of sum(F).
  GaussianParams g;
  g.means = gaussians.means.detach();
  g.quats = gaussians.quats.detach();
  g.log_scales = gaussians.log_scales.detach();
  g.opacity_logits = gaussians.opacity_logits.detach();
  g.sh = gaussians.sh.detach().narrow(1, 0, 1).contiguous();
  if (gaussians.opacity_gate.defined()) g.opacity_gate = gaussians.opacity_gate.detach();
  const at::Tensor ones = at::ones({g.means.size(0), 1}, g.means.options()).requires_grad_(true);
  g.features = ones;
  RenderSettings settings;
  settings.sh_degree = 0;
  settings.features = true;
  settings.depth = false;
  at::Tensor total = at::zeros({g.means.size(0)}, g.means.options());
  for (const RasterCamera& camera : cameras) {
    const RenderResult r = render(g, camera, settings);
    r.features.sum().backward();
    total += ones.grad().select(1, 0);
    ones.mutable_grad().zero_();
  }
  return total;
}

at::Tensor inverseContributionWeights(const at::Tensor& contribution, double gamma) {
  if (!(gamma >= 0)) {
    throw Error("<config>", "l0_importance", "a non-negative exponent", std::to_string(gamma));
  }
  const int64_t n = contribution.numel();
  if (n == 0 || gamma == 0) return at::ones_like(contribution);
  double scale = contribution.median().item<double>();
  if (!(scale > 0)) {
    const at::Tensor positive = contribution.masked_select(contribution > 0);
    if (positive.numel() == 0) return at::ones_like(contribution);
    scale = positive.mean().item<double>();
  }
  const at::Tensor w = (1 + contribution / scale).pow(-gamma);
  return w / w.mean();
}

}  // namespace gaussians
}  // namespace sadsplat
