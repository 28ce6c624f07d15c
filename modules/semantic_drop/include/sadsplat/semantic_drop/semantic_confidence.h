#pragma once
/// \file semantic_confidence.h
/// \brief P_confidence of each Gaussian (paper, "Semantic Confidence Drop Module"): project its
/// centre into every view that has a confidence map (H x W x C class scores in [0, 1]), take the
/// maximum over classes at that pixel times the Gaussian's opacity, and average over the views
/// in which the centre is visible (in front of the camera, inside the image). A Gaussian visible
/// in no such view gets 0.

#include <ATen/ATen.h>

#include <vector>

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace semantic_drop {

/// \brief Confidence [N] in [0, 1].
/// \param[in] means [N, 3] centres
/// \param[in] opacities [N] activated opacities in [0, 1]
/// \param[in] cameras one per confidence map
/// \param[in] confidence_maps [H, W, C] class scores per camera, matching its size, or [H, W]
///            maps that already hold the maximum over classes
/// \param[out] seen if given, [N] bool: visible in at least one of the views
/// \throws sadsplat::Error on mismatched sizes
at::Tensor semanticConfidence(const at::Tensor& means, const at::Tensor& opacities,
                              const std::vector<gaussians::RasterCamera>& cameras,
                              const std::vector<at::Tensor>& confidence_maps,
                              at::Tensor* seen = nullptr);

/// \brief One-hot confidence maps [H, W, C] from a label map (the stand-in for the pseudo-label
/// backend's maps: 1 for the labelled class, 0 elsewhere and on ignored pixels).
at::Tensor oneHotConfidence(const at::Tensor& labels, int num_classes);

}  // namespace semantic_drop
}  // namespace sadsplat
