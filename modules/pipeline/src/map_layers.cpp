#include "map_layers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/common/order_statistics.h"
#include "sadsplat/eval/object_scores.h"
#include "sadsplat/geo/ground_model.h"
#include "sadsplat/geo/map_objects.h"
#include "sadsplat/pipeline/labelled_cloud.h"

namespace sadsplat {
namespace pipeline {

OrthoRenderOptions checkedRenderOptions(const OrthoRunOptions& o, const char* what) {
  OrthoRenderOptions r;
  r.height = parseOrthoSurface(o.height, "--height");
  r.classes = parseOrthoClassSource(o.class_from, "--class-from");
  if (o.min_views < 0) {
    throw Error(what, "--min-views", "a number of photos >= 0", std::to_string(o.min_views));
  }
  if (!(o.min_spread >= 0 && o.min_spread <= 360)) {
    throw Error(what, "--min-spread", "degrees in [0, 360]", std::to_string(o.min_spread));
  }
  if (!(o.depth_tolerance > 0 && o.depth_tolerance <= 1)) {
    throw Error(what, "--depth-tolerance", "a share of the depth in (0, 1]",
                std::to_string(o.depth_tolerance));
  }
  if (!(o.on_surface >= 0 && std::isfinite(o.on_surface))) {
    throw Error(what, "--on-surface", "a distance >= 0 in scene units (0: off)",
                std::to_string(o.on_surface));
  }
  if (!(o.raised_check >= 0 && o.raised_check <= 1)) {
    throw Error(what, "--raised-check", "a share of the raised class's height in [0, 1] (0: off)",
                std::to_string(o.raised_check));
  }
  if (!(o.pit_depth >= 0 && std::isfinite(o.pit_depth))) {
    throw Error(what, "--pit-depth", "a depth >= 0 in map units (0: off)",
                std::to_string(o.pit_depth));
  }
  if (!(o.spike_height >= 0 && std::isfinite(o.spike_height))) {
    throw Error(what, "--spike-height", "a height >= 0 in map units (0: off)",
                std::to_string(o.spike_height));
  }
  if (!(o.spike_clearance >= 0 && std::isfinite(o.spike_clearance))) {
    throw Error(what, "--spike-clearance", "a distance >= 0 in map units",
                std::to_string(o.spike_clearance));
  }
  if (o.trim_whole_under < 0) {
    throw Error(what, "--trim-whole-under", "a number of Gaussians >= 0",
                std::to_string(o.trim_whole_under));
  }
  if (!(o.object_step >= 0 && std::isfinite(o.object_step))) {
    throw Error(what, "--object-step", "a height step >= 0 in map units (0: plain regions)",
                std::to_string(o.object_step));
  }
  if (!(o.ground_window > 0 && std::isfinite(o.ground_window))) {
    throw Error(what, "--ground-window", "a window side > 0 in map units",
                std::to_string(o.ground_window));
  }
  r.raised_share = o.raised_check;
  r.pit_depth = o.pit_depth;
  r.spike_height = o.spike_height;
  r.spike_clearance = o.spike_clearance;
  r.ground_window = o.ground_window;
  r.min_views = o.min_views;
  r.min_spread_degrees = o.min_spread;
  r.max_surface_gap = o.on_surface;
  r.depth_tolerance = o.depth_tolerance;
  return r;
}

std::vector<int> classIdsOf(const std::vector<std::string>& names,
                            const std::vector<ClassInfo>& classes, const char* what,
                            const char* flag) {
  std::vector<int> ids;
  for (const std::string& name : names) {
    const auto it = std::find_if(classes.begin(), classes.end(),
                                 [&](const ClassInfo& c) { return c.name == name; });
    if (it == classes.end()) {
      std::string known;
      for (const ClassInfo& c : classes) known += (known.empty() ? "" : ", ") + c.name;
      throw Error(what, flag, "class names of the model (" + known + ")", name);
    }
    ids.push_back(static_cast<int>(it - classes.begin()));
  }
  return ids;
}

std::vector<std::string> trimClasses(const OrthoRunOptions& o,
                                     const std::vector<ClassInfo>& classes) {
  if (o.trim.empty() || o.trim == std::vector<std::string>{"none"}) return {};
  if (o.trim == std::vector<std::string>{"auto"}) {
    for (const ClassInfo& c : classes) {
      if (c.name == "building") return {"building"};
    }
    return {};
  }
  return o.trim;
}

pcl::PointCloud<GaussianPoint> setGaussianClasses(OrthoRenderOptions& render,
                                                  const OrthoRunOptions& o,
                                                  const gaussians::Trainer& trainer,
                                                  const io::Scene& scene, const char* what) {
  const std::vector<std::string> names = trimClasses(o, scene.classes);
  for (const std::string& n : o.trim) {
    if ((n == "auto" || n == "none") && o.trim.size() > 1) {
      throw Error(what, "--trim", "class names, or auto / none alone", n + " among others");
    }
  }
  const bool views = render.classes == OrthoClassSource::kViews;
  if ((names.empty() && !views) || trainer.numClasses() == 0) return {};
  if (!names.empty()) {
    render.trim_classes = classIdsOf(names, scene.classes, what, "--trim");
    render.trim_step = o.object_step;
    render.trim_whole_under = static_cast<std::size_t>(o.trim_whole_under);
  }
  pcl::PointCloud<GaussianPoint> cloud = labelledCloud(trainer, scene, o.progress);
  render.gaussian_classes.resize(cloud.size());
  for (std::size_t g = 0; g < cloud.size(); ++g) render.gaussian_classes[g] = cloud[g].label;
  return cloud;
}

void addRenderOptions(nlohmann::json& j, const OrthoRunOptions& o, const OrthoImages& img,
                      const std::vector<ClassInfo>& classes) {
  j["height_from"] = o.height;  // --height (the surface the DSM takes)
  j["class_from"] = o.class_from;
  j["min_views"] = o.min_views;
  j["min_spread_degrees"] = o.min_spread;
  j["depth_tolerance"] = o.depth_tolerance;
  j["on_surface_m"] = o.on_surface;
  j["raised_check"] = o.raised_check;
  j["pit_depth"] = o.pit_depth;
  j["spike_height"] = o.spike_height;
  if (o.spike_height > 0) j["spike_clearance"] = o.spike_clearance;
  j["trim"] = trimClasses(o, classes);
  if (!j["trim"].empty()) {
    j["trim_step_m"] = o.object_step;
    j["trim_whole_under"] = o.trim_whole_under;
    j["trimmed_share"] = img.classes.empty() ? 0.0 : double(img.trimmed_cells) / img.classes.size();
  }
  if (o.raised_check <= 0 && o.pit_depth <= 0 && o.spike_height <= 0) return;
  j["ground_window"] = o.ground_window;
  nlohmann::json heights = nlohmann::json::object(), raised = nlohmann::json::array();
  for (std::size_t c = 0; c < img.class_height_above_ground.size() && c < classes.size(); ++c) {
    const double h = img.class_height_above_ground[c];
    heights[classes[c].name] = std::isfinite(h) ? nlohmann::json(h) : nlohmann::json(nullptr);
  }
  for (int c : img.raised_classes) raised.push_back(classes.at(c).name);
  j["class_height_above_ground"] = heights;
  j["raised_classes"] = raised;
  const std::size_t n = img.classes.size();
  j["raised_lowered_share"] = n ? double(img.lowered_cells) / n : 0.0;
  j["pit_filled_share"] = n ? double(img.filled_pits) / n : 0.0;
  j["near_ground_share"] = img.near_ground;
  j["raised_check_applied"] = o.raised_check > 0 && img.near_ground >= geo::kMinNearGround;
  j["pit_depth_applied"] = o.pit_depth > 0 && img.near_ground >= geo::kMinNearGround;
  j["spike_lowered_share"] = n ? double(img.lowered_spikes) / n : 0.0;
  j["spike_height_applied"] = o.spike_height > 0 && img.near_ground >= geo::kMinNearGround;
}

ClassObjects classObjects(const OrthoImages& img, const std::vector<int>& wanted, double step,
                          std::size_t min_cells) {
  const std::size_t n = img.classes.size();
  ClassObjects out;
  out.labels.assign(n, 0);
  geo::MapObjectOptions options;
  options.max_step = step;
  options.min_cells = min_cells;
  for (const int c : wanted) {
    std::vector<std::uint8_t> mask(n, 0);
    for (std::size_t i = 0; i < n; ++i) mask[i] = img.covered[i] && img.classes[i] == c;
    const std::vector<int> labels =
        geo::mapObjects(mask, img.elevation, img.width, img.height, options);
    const int first = static_cast<int>(out.objects.size());
    int count = 0;
    for (const int l : labels) count = std::max(count, l);
    std::vector<std::vector<float>> heights(static_cast<std::size_t>(count));
    std::vector<std::vector<float>> above(static_cast<std::size_t>(count));
    for (std::size_t i = 0; i < n; ++i) {
      if (!labels[i]) continue;
      out.labels[i] = first + labels[i];
      const auto k = static_cast<std::size_t>(labels[i]) - 1;
      heights[k].push_back(img.elevation[i]);
      if (i < img.ground.size() && std::isfinite(img.ground[i])) {
        above[k].push_back(img.elevation[i] - img.ground[i]);
      }
    }
    for (std::size_t k = 0; k < heights.size(); ++k) {
      geo::MapObjectAttributes a;
      a.class_id = c;
      a.height = quantileInPlace(heights[k], 0.5);
      if (!above[k].empty()) a.height_above_ground = quantileInPlace(above[k], 0.5);
      out.objects.push_back(a);
    }
  }
  return out;
}

std::vector<std::vector<std::size_t>> objectGaussians(const pcl::PointCloud<GaussianPoint>& cloud,
                                                      const OrthoGrid& grid,
                                                      const ClassObjects& objects,
                                                      double min_opacity) {
  const std::size_t cells = static_cast<std::size_t>(grid.width) * grid.height;
  if (objects.labels.size() != cells) {
    throw Error("<map objects>", "labels", std::to_string(cells) + " cells (the grid's)",
                std::to_string(objects.labels.size()));
  }
  // Opacity is stored as a logit; 0 keeps every Gaussian.
  const double min_logit = min_opacity > 0 ? std::log(min_opacity / (1 - min_opacity))
                                           : -std::numeric_limits<double>::infinity();
  std::vector<std::vector<std::size_t>> groups(objects.objects.size());
  for (std::size_t g = 0; g < cloud.size(); ++g) {
    const GaussianPoint& p = cloud[g];
    if (!(p.opacity >= min_logit)) continue;
    const std::array<double, 3> m = grid.frame.toMap({p.x, p.y, p.z});
    const double i = std::floor((m[0] - grid.x0) / grid.gsd);
    const double j = std::floor((grid.y0 - m[1]) / grid.gsd);
    if (!(i >= 0 && i < grid.width && j >= 0 && j < grid.height)) continue;
    const int k =
        objects.labels[static_cast<std::size_t>(j) * grid.width + static_cast<std::size_t>(i)];
    if (k <= 0) continue;
    if (objects.objects[static_cast<std::size_t>(k) - 1].class_id != static_cast<int>(p.label)) {
      continue;
    }
    groups[static_cast<std::size_t>(k) - 1].push_back(g);
  }
  return groups;
}

std::vector<std::size_t> cellsOutsideObjectHulls(const pcl::PointCloud<GaussianPoint>& cloud,
                                                 const OrthoGrid& grid, const OrthoImages& img,
                                                 const std::vector<int>& classes, double step,
                                                 std::size_t min_cells, std::size_t whole_under) {
  const ClassObjects objects = classObjects(img, classes, step, min_cells);
  const std::vector<std::vector<std::size_t>> groups =
      objectGaussians(cloud, grid, objects, kObjectMinOpacity);
  // Each object's hull in grid cells (x right, y down), as geo::cellsOutsideHulls takes them.
  std::vector<std::vector<std::array<double, 2>>> hulls(groups.size());
  for (std::size_t k = 0; k < groups.size(); ++k) {
    if (groups[k].size() < kMinHullGaussians) continue;
    std::vector<std::array<double, 2>> xy;
    for (const std::size_t g : groups[k]) {
      const std::array<double, 3> m = grid.frame.toMap({cloud[g].x, cloud[g].y, cloud[g].z});
      xy.push_back({(m[0] - grid.x0) / grid.gsd, (grid.y0 - m[1]) / grid.gsd});
    }
    hulls[k] = eval::convexHull(std::move(xy));
  }
  std::vector<std::size_t> outside = geo::cellsOutsideHulls(objects.labels, grid.width, hulls);
  // Objects with fewer than whole_under Gaussians over them go whole.
  for (std::size_t i = 0; i < objects.labels.size(); ++i) {
    const int label = objects.labels[i];
    if (label > 0 && groups[static_cast<std::size_t>(label) - 1].size() < whole_under) {
      outside.push_back(i);
    }
  }
  std::sort(outside.begin(), outside.end());
  outside.erase(std::unique(outside.begin(), outside.end()), outside.end());
  return outside;
}

}  // namespace pipeline
}  // namespace sadsplat
