#include "sadsplat/pipeline/raised_gaussians.h"

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/pipeline/opened_run.h"

namespace sadsplat {
namespace pipeline {

geo::LowRaisedCells findLowRaisedGaussians(const pcl::PointCloud<GaussianPoint>& cloud,
                                           const io::Scene& scene, int num_classes,
                                           const RaisedGaussianOptions& options) {
  if (!(options.share >= 0 && options.share <= 1)) {
    throw Error("<raised check>", "share", "in [0, 1]", std::to_string(options.share));
  }
  const geo::MapFrame frame = geo::localMapFrame(geo::sceneUp(scene));
  const std::size_t n = cloud.size();
  std::vector<float> e(n), north(n), up(n);
  std::vector<std::uint8_t> opaque(n), classes(n, 255);
  for (std::size_t i = 0; i < n; ++i) {
    const GaussianPoint& p = cloud[i];
    const auto local = frame.toLocal({p.x, p.y, p.z});
    e[i] = static_cast<float>(local[0]);
    north[i] = static_cast<float>(local[1]);
    up[i] = static_cast<float>(local[2]);
    opaque[i] = 1.f / (1.f + std::exp(-p.opacity)) >= options.opaque;
    if (p.label < static_cast<std::uint32_t>(num_classes) && p.label < 255)
      classes[i] = static_cast<std::uint8_t>(p.label);
  }
  if (options.share == 0 || n == 0) return {};
  const std::vector<float> ground =
      geo::groundUnderPoints(e, north, up, opaque, options.cell, options.window);
  return geo::findLowRaisedCells(classes, up, ground, num_classes, options.raised_height,
                                 options.share, options.min_near_ground);
}

pcl::PointCloud<GaussianPoint> withoutLowRaisedGaussians(
    const std::string& run_dir, const pcl::PointCloud<GaussianPoint>& model,
    const RaisedGaussianOptions& options, std::ostream* report) {
  const io::RunDirectory run(run_dir);
  const io::RunRecord record = run.readRecord();
  const io::Scene scene = loadScene(record.scene, record.scale, nullptr, ScenePixels::kLeftOnDisk);
  const int classes = static_cast<int>(scene.classes.size());
  const geo::LowRaisedCells low = findLowRaisedGaussians(model, scene, classes, options);
  std::vector<char> drop(model.size(), 0);
  for (const std::size_t i : low.cells) drop[i] = 1;
  pcl::PointCloud<GaussianPoint> kept;
  kept.header = model.header;
  for (std::size_t i = 0; i < model.size(); ++i) {
    if (!drop[i]) kept.push_back(model[i]);
  }
  if (report != nullptr) {
    *report << "raised-class check (" << options.share << "): " << low.cells.size()
            << " Gaussians of a raised class at ground height left out (raised:";
    for (const int c : low.raised) *report << " " << scene.classes[c].name;
    if (low.raised.empty()) *report << " none";
    *report << "; " << static_cast<int>(std::lround(100 * low.near_ground))
            << " % of the labelled Gaussians near the ground";
    if (low.near_ground < options.min_near_ground) *report << ": too few, nothing checked";
    *report << ")\n";
  }
  return kept;
}

}  // namespace pipeline
}  // namespace sadsplat
