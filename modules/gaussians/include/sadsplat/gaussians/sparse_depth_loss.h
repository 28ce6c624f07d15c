#pragma once
/// \file sparse_depth_loss.h
/// \brief Not the paper: a depth loss against the scene's sparse points (the depth supervision
/// from structure-from-motion points of DNGaussian, FSGS and gsplat's `depth_loss`). Where a
/// capture sees the ground from one side only (an orbit's periphery, a survey's edge), the
/// photometric loss cannot tell a Gaussian on the ground from one floating along the rays above
/// it; the points the photos triangulated can.

#include <ATen/ATen.h>

#include "sadsplat/gaussians/view_coverage.h"

namespace sadsplat {
namespace gaussians {

/// \brief The mean over the samples of |D(p) - z| / z: D the rendered expected depth (`depth`,
/// [H, W], as RenderResult::depth) at the sample's pixel p, z the point's camera depth
/// (`samples` as visibleSparseDepths() gives them, on the device of `depth`). Relative, so that
/// far and near points weigh alike and the loss does not depend on the scene's units.
/// Differentiable in `depth`; a 0-dimensional tensor, 0 without samples.
/// The samples must be visibleSparseDepths()'s for a camera of `depth`'s size (not checked: that
/// would make the host wait for the device at every step).
/// \throws sadsplat::Error when `depth` is not [H, W]
at::Tensor sparseDepthLoss(const at::Tensor& depth, const SparseDepthSamples& samples);

}  // namespace gaussians
}  // namespace sadsplat
