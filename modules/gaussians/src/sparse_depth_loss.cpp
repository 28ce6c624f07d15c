#include "sadsplat/gaussians/sparse_depth_loss.h"

#include <string>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {

at::Tensor sparseDepthLoss(const at::Tensor& depth, const SparseDepthSamples& samples) {
  if (depth.dim() != 2) {
    throw Error("<sparse depth loss>", "depth", "an [H, W] image",
                std::to_string(depth.dim()) + "-d");
  }
  if (samples.size() == 0) return at::zeros({}, depth.options());
  // No range check here (it would make the host wait for the device every step): the samples
  // come from visibleSparseDepths() for a camera of this image's size, inside it by construction.
  const at::Tensor flat = depth.reshape({-1});
  const at::Tensor z = samples.depths.to(depth.scalar_type());
  return ((flat.index_select(0, samples.pixels) - z).abs() / z).mean();
}

}  // namespace gaussians
}  // namespace sadsplat
