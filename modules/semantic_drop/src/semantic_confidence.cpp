#include "sadsplat/semantic_drop/semantic_confidence.h"

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/raster_math.h"

namespace sadsplat {
namespace semantic_drop {

at::Tensor semanticConfidence(const at::Tensor& means, const at::Tensor& opacities,
                              const std::vector<gaussians::RasterCamera>& cameras,
                              const std::vector<at::Tensor>& confidence_maps, at::Tensor* seen) {
  if (cameras.size() != confidence_maps.size()) {
    throw Error("<semantic confidence>", "confidence maps", "one per camera",
                std::to_string(confidence_maps.size()) + " for " + std::to_string(cameras.size()) +
                    " cameras");
  }
  const auto opts = means.options();
  at::Tensor sum = at::zeros({means.size(0)}, opts), count = at::zeros({means.size(0)}, opts);
  for (std::size_t v = 0; v < cameras.size(); ++v) {
    const auto& cam = cameras[v];
    const at::Tensor& map = confidence_maps[v];
    if ((map.dim() != 3 && map.dim() != 2) || map.size(0) != cam.height ||
        map.size(1) != cam.width) {
      throw Error("<semantic confidence>", "confidence map " + std::to_string(v),
                  "[H, W, C] or [H, W] with the camera's " + std::to_string(cam.width) + "x" +
                      std::to_string(cam.height),
                  std::to_string(map.dim()) + "-d " + std::to_string(map.size(0)) + "x" +
                      std::to_string(map.size(1)));
    }
    const double q[4] = {cam.qvec[0], cam.qvec[1], cam.qvec[2], cam.qvec[3]};
    double R[9];
    gaussians::raster::quatToRotation(q, R);
    const at::Tensor Rt =
        at::tensor({R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]}, opts).view({3, 3});
    const at::Tensor t = at::tensor({cam.tvec[0], cam.tvec[1], cam.tvec[2]}, opts);
    const at::Tensor p = at::matmul(means, Rt) + t;
    const at::Tensor z = p.select(1, 2);
    const at::Tensor u = cam.fx * p.select(1, 0) / z + cam.cx;
    const at::Tensor w = cam.fy * p.select(1, 1) / z + cam.cy;
    const at::Tensor visible =
        (z > cam.near_plane) & (u >= 0) & (u < cam.width) & (w >= 0) & (w < cam.height);
    const at::Tensor pixel =
        (w.clamp(0, cam.height - 1).floor() * cam.width + u.clamp(0, cam.width - 1).floor())
            .to(at::kLong);
    const at::Tensor m = map.to(means.device(), opts.dtype().toScalarType());
    const at::Tensor best = (m.dim() == 3 ? std::get<0>(m.max(2)) : m).reshape({-1});
    const at::Tensor value = best.index_select(0, pixel) * opacities;
    sum += at::where(visible, value, at::zeros_like(value));
    count += visible.to(opts.dtype());
  }
  if (seen != nullptr) *seen = count > 0;
  return at::where(count > 0, sum / count.clamp_min(1), at::zeros_like(sum));
}

at::Tensor oneHotConfidence(const at::Tensor& labels, int num_classes) {
  const at::Tensor valid = labels >= 0;
  at::Tensor onehot =
      at::zeros({labels.size(0), labels.size(1), num_classes}, labels.options().dtype(at::kFloat));
  onehot.scatter_(2, labels.clamp_min(0).unsqueeze(2), 1.0);
  return onehot * valid.unsqueeze(2).to(at::kFloat);
}

}  // namespace semantic_drop
}  // namespace sadsplat
