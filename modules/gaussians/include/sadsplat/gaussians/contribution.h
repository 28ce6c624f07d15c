#pragma once
/// \file contribution.h
/// \brief How much of a set of views each Gaussian makes: the sum, over the views and their
/// pixels, of its blending weight alpha_i * T_i (T_i the transmittance in front of it). A Gaussian
/// that no view sees, or that lies behind opaque ones, scores 0; one that alone covers k pixels
/// opaquely scores about k. The pruning score of the drop's recovery phase and the weights of the
/// importance-weighted L0 term (in the spirit of the contribution scores of LightGaussian and
/// PUP-3DGS, computed with sadsplat's own rasterizer).

#include <ATen/ATen.h>

#include <functional>
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

/// \brief Per Gaussian, the sum over the pixels of one camera of its blending weight times each
/// of K per-pixel values: sum_p alpha_i T_i (p) values(p, k). With values 1 it is the Gaussian's
/// part of blendingWeightSums for this camera; divided by that, the mean value over what the
/// Gaussian draws (e.g. the rendered depth there).
/// \param[in] gaussians the Gaussians (any device; no gradient is taken into them)
/// \param[in] camera the view
/// \param[in] values [H, W, K] float, K >= 1 (any device)
/// \return float [N, K] on the device of the Gaussians
at::Tensor weightedPixelSums(const GaussianParams& gaussians, const RasterCamera& camera,
                             const at::Tensor& values);

/// \brief Per Gaussian and class, the sum of its blending weights over the pixels that a class
/// map of each camera gives that class: how much of what the views show as class c the
/// Gaussian makes. Summed over the classes it is blendingWeightSums over the labelled pixels.
/// \param[in] gaussians the Gaussians (any device; no gradient is taken into them)
/// \param[in] cameras the views to sum over
/// \param[in] class_map the class of every pixel of camera k ([H, W] int64, any device; a value
/// outside [0, num_classes) counts for no class), asked for once per camera in order
/// \param[in] num_classes > 0
/// \return float [N, num_classes] on the device of the Gaussians, >= 0 (in pixels)
at::Tensor classWeightSums(const GaussianParams& gaussians,
                           const std::vector<RasterCamera>& cameras,
                           const std::function<at::Tensor(std::size_t)>& class_map,
                           int num_classes);

/// \brief Per Gaussian, how far its centre lies from the surface the views render where it
/// draws: sum_k |sum_p w(p) (D_k(p) - z_k)| / sum_k sum_p w(p), with w the Gaussian's blending
/// weight in camera k, D_k camera k's rendered depth map and z_k the Gaussian's depth in camera
/// k. Per camera that is the gap between the Gaussian's depth and the mean rendered depth over
/// the pixels it draws, averaged over the cameras by how much it draws in each. A Gaussian on
/// the surface the views agree on scores about its own thickness; one floating in front of that
/// surface or sunk behind it scores the gap.
/// \param[in] gaussians the Gaussians (any device; no gradient is taken into them)
/// \param[in] cameras pinhole views to sum over
/// \param[in] depth_map camera k's rendered depth ([H, W] float, any device), asked for once per
/// camera in order
/// \return float [N] on the device of the Gaussians, in scene units; +inf where no camera draws
/// the Gaussian
at::Tensor depthResiduals(const GaussianParams& gaussians, const std::vector<RasterCamera>& cameras,
                          const std::function<at::Tensor(std::size_t)>& depth_map);

/// \brief The gaps of both surface checks from their per-camera sums: per Gaussian
/// sum_k |G_k| / sum_k W_k, where (W_k, G_k) = camera_sums(k) are its blend weights and its
/// weighted signed gaps (surface depth - its depth) summed over camera k's pixels.
/// \param[in] n the number of Gaussians
/// \param[in] device where the result lives
/// \param[in] cameras how many cameras to ask camera_sums for, in order
/// \param[in] camera_sums [n, 2] per camera (any floating dtype, any device)
/// \return float [n] on `device`; +inf where no camera has weight for the Gaussian
at::Tensor gapsFromCameraSums(std::int64_t n, at::Device device, std::size_t cameras,
                              const std::function<at::Tensor(std::size_t)>& camera_sums);

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
