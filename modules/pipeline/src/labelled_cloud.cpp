#include "sadsplat/pipeline/labelled_cloud.h"

#include <vector>

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace pipeline {

pcl::PointCloud<GaussianPoint> labelledCloud(const gaussians::Trainer& trainer,
                                             const io::Scene& scene) {
  pcl::PointCloud<GaussianPoint> cloud = trainer.toCloud();
  if (trainer.numClasses() == 0) return cloud;
  std::vector<gaussians::RasterCamera> cameras;
  for (const io::View& view : scene.views) {
    if (view.train) cameras.push_back(gaussians::RasterCamera::fromPinhole(view.camera));
  }
  if (cameras.empty()) return cloud;
  const at::Tensor weights = trainer.renderedClassWeights(cameras).to(at::kFloat).contiguous();
  const at::Tensor seen = (weights.sum(1) > 0).contiguous();
  const at::Tensor best = weights.argmax(1).contiguous();
  const bool* s = seen.data_ptr<bool>();
  const int64_t* b = best.data_ptr<int64_t>();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (s[i]) cloud[i].label = static_cast<std::uint32_t>(b[i]);
  }
  return cloud;
}

}  // namespace pipeline
}  // namespace sadsplat
