#pragma once
/// \file contribution.h
/// \brief How much of a set of views each Gaussian makes: the sum, over the views and their
/// pixels, of its blending weight alpha_i * T_i (T_i the transmittance in front of it). A Gaussian
/// that no view sees, or that lies behind opaque ones, scores 0; one that alone covers k pixels
/// opaquely scores about k. The pruning score of the drop's recovery phase and the weights of the
/// importance-weighted L0 term (in the spirit of the contribution scores of LightGaussian and
/// PUP-3DGS, computed with sadsplat's own rasterizer).

#include <ATen/ATen.h>

#include <vector>

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace gaussians {

/// \brief Per Gaussian, the sum of its blending weights over every pixel of every camera.
/// The colours are not needed (rendered at SH degree 0); `opacity_gate` is applied when given.
/// \param[in] gaussians the Gaussians (any device; no gradient is taken into them)
/// \param[in] cameras the views to sum over
/// \return float [N] on the device of the Gaussians, >= 0 (in pixels)
at::Tensor blendingWeightSums(const GaussianParams& gaussians,
                              const std::vector<RasterCamera>& cameras);

/// \brief Weights that fall with the contribution: w = (1 + c / median(c))^-gamma, scaled to mean
/// 1. A Gaussian that contributes nothing gets the largest weight, one at the median 2^-gamma of
/// it; gamma 0 gives all ones. Where the median is 0 (most Gaussians contribute nothing), the mean
/// of the positive contributions takes its place; all ones when none is positive.
/// \param[in] contribution [N] >= 0 (blendingWeightSums)
/// \param[in] gamma >= 0
/// \return [N], same dtype and device
at::Tensor inverseContributionWeights(const at::Tensor& contribution, double gamma);

}  // namespace gaussians
}  // namespace sadsplat
