#include "sadsplat/gaussians/contribution.h"

#include <c10/core/GradMode.h>

#include <limits>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/view_coverage.h"

namespace sadsplat {
namespace gaussians {

namespace {

// The Gaussians without gradients and their colour's first SH coefficient only, to render
// `channels` features of 1 per Gaussian (`ones`, which takes the gradient).
GaussianParams withUnitFeatures(const GaussianParams& gaussians, int64_t channels,
                                at::Tensor* ones) {
  GaussianParams g;
  g.means = gaussians.means.detach();
  g.quats = gaussians.quats.detach();
  g.log_scales = gaussians.log_scales.detach();
  g.opacity_logits = gaussians.opacity_logits.detach();
  g.sh = gaussians.sh.detach().narrow(1, 0, 1).contiguous();
  if (gaussians.opacity_gate.defined()) g.opacity_gate = gaussians.opacity_gate.detach();
  *ones = at::ones({g.means.size(0), channels}, g.means.options()).requires_grad_(true);
  g.features = *ones;
  return g;
}

RenderSettings featuresOnly() {
  RenderSettings settings;
  settings.sh_degree = 0;
  settings.features = true;
  settings.depth = false;
  return settings;
}

}  // namespace

at::Tensor blendingWeightSums(const GaussianParams& gaussians,
                              const std::vector<RasterCamera>& cameras) {
  c10::AutoGradMode grad_mode(true);
  // A one-channel feature of 1 per Gaussian composites to F(pixel) = sum_i 1 * alpha_i T_i, so
  // dF/d(feature_i) = alpha_i T_i, summed over the pixels by the backward pass of sum(F).
  at::Tensor ones;
  const GaussianParams g = withUnitFeatures(gaussians, 1, &ones);
  const RenderSettings settings = featuresOnly();
  at::Tensor total = at::zeros({g.means.size(0)}, g.means.options());
  for (const RasterCamera& camera : cameras) {
    const RenderResult r = render(g, camera, settings);
    r.features.sum().backward();
    total += ones.grad().select(1, 0);
    ones.mutable_grad().zero_();
  }
  return total;
}

at::Tensor weightedPixelSums(const GaussianParams& gaussians, const RasterCamera& camera,
                             const at::Tensor& values) {
  if (values.dim() != 3 || values.size(0) != camera.height || values.size(1) != camera.width ||
      values.size(2) < 1) {
    throw Error(
        "<weightedPixelSums>", "values",
        "[" + std::to_string(camera.height) + ", " + std::to_string(camera.width) + ", K >= 1]",
        "another shape");
  }
  c10::AutoGradMode grad_mode(true);
  // K features of 1 per Gaussian composite to F_k(p) = sum_i alpha_i T_i (p); the gradient of
  // sum_p F_k(p) values(p, k) with respect to feature (i, k) is sum_p alpha_i T_i (p) values(p, k).
  at::Tensor ones;
  const GaussianParams g = withUnitFeatures(gaussians, values.size(2), &ones);
  const RenderResult r = render(g, camera, featuresOnly());
  (r.features * values.to(g.means.device(), g.means.scalar_type())).sum().backward();
  return ones.grad();
}

at::Tensor classWeightSums(const GaussianParams& gaussians,
                           const std::vector<RasterCamera>& cameras,
                           const std::function<at::Tensor(std::size_t)>& class_map,
                           int num_classes) {
  if (num_classes <= 0) {
    throw Error("<classWeightSums>", "num_classes", "a positive count",
                std::to_string(num_classes));
  }
  const at::TensorOptions options = gaussians.means.options();
  at::Tensor total = at::zeros({gaussians.means.size(0), num_classes}, options);
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    const RasterCamera& camera = cameras[k];
    const at::Tensor classes = class_map(k).to(options.device(), at::kLong);
    if (classes.dim() != 2 || classes.size(0) != camera.height || classes.size(1) != camera.width) {
      throw Error("<classWeightSums>", "class map of camera " + std::to_string(k),
                  "[" + std::to_string(camera.height) + ", " + std::to_string(camera.width) + "]",
                  "another shape");
    }
    const at::Tensor valid = ((classes >= 0) & (classes < num_classes)).unsqueeze(2);
    const at::Tensor onehot =
        at::one_hot(classes.clamp(0, num_classes - 1), num_classes).to(options.dtype()) *
        valid.to(options.dtype());
    total += weightedPixelSums(gaussians, camera, onehot);
  }
  return total;
}

at::Tensor depthResiduals(const GaussianParams& gaussians, const std::vector<RasterCamera>& cameras,
                          const std::function<at::Tensor(std::size_t)>& depth_map) {
  const at::Tensor means = gaussians.means.detach().to(at::kDouble);
  return gapsFromCameraSums(means.size(0), means.device(), cameras.size(), [&](std::size_t k) {
    const RasterCamera& camera = cameras[k];
    const at::Tensor depth = depth_map(k).to(gaussians.means.device(), at::kFloat);
    if (depth.dim() != 2 || depth.size(0) != camera.height || depth.size(1) != camera.width) {
      throw Error("<depthResiduals>", "depth map of camera " + std::to_string(k),
                  "[" + std::to_string(camera.height) + ", " + std::to_string(camera.width) + "]",
                  "another shape");
    }
    const at::Tensor sums =
        weightedPixelSums(gaussians, camera, at::stack({at::ones_like(depth), depth}, 2))
            .to(at::kDouble);
    const at::Tensor w = sums.select(1, 0);
    return at::stack({w, sums.select(1, 1) - w * cameraDepths(means, camera)}, 1);
  });
}

at::Tensor gapsFromCameraSums(std::int64_t n, at::Device device, std::size_t cameras,
                              const std::function<at::Tensor(std::size_t)>& camera_sums) {
  at::Tensor weight = at::zeros({n}, at::TensorOptions().dtype(at::kDouble).device(device));
  at::Tensor gap = at::zeros_like(weight);
  for (std::size_t k = 0; k < cameras; ++k) {
    const at::Tensor sums = camera_sums(k).to(device, at::kDouble);
    weight += sums.select(1, 0);
    gap += sums.select(1, 1).abs();
  }
  return at::where(weight > 0, gap / weight.clamp_min(1e-30),
                   at::full_like(weight, std::numeric_limits<double>::infinity()))
      .to(at::kFloat);
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
