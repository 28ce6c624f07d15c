#include "sadsplat/gaussians/initialization.h"

#include <pcl/kdtree/kdtree_flann.h>

#include <cmath>
#include <random>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {
namespace {
constexpr float kShC0 = 0.28209479177387814f;  // 1 / (2 sqrt(pi)), the degree-0 SH basis
}  // namespace

float rgbToShDc(float rgb) { return (rgb - 0.5f) / kShC0; }
float shDcToRgb(float dc) { return dc * kShC0 + 0.5f; }

pcl::PointCloud<GaussianPoint> initialCloud(const std::vector<io::ScenePoint>& points,
                                            const InitOptions& options) {
  const int k = options.scale_neighbours;
  if (k < 1 || points.size() < static_cast<std::size_t>(k) + 1) {
    throw Error("<scene>", "sparse points",
                "at least " + std::to_string(k + 1) + " points to initialise Gaussians",
                std::to_string(points.size()));
  }
  if (!(options.initial_opacity > 0.f && options.initial_opacity < 1.f)) {
    throw Error("<init options>", "initial_opacity", "a value in (0, 1)",
                std::to_string(options.initial_opacity));
  }
  auto cloud = std::make_shared<pcl::PointCloud<GaussianPoint>>();
  cloud->resize(points.size());
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<float> noise(0.f, options.feature_stddev);
  const float opacity_logit = std::log(options.initial_opacity / (1.f - options.initial_opacity));
  for (std::size_t i = 0; i < points.size(); ++i) {
    GaussianPoint& g = (*cloud)[i];
    g.x = points[i].xyz[0];
    g.y = points[i].xyz[1];
    g.z = points[i].xyz[2];
    for (int c = 0; c < 3; ++c) g.f_dc[c] = rgbToShDc(points[i].rgb[c] / 255.f);
    g.opacity = opacity_logit;
    for (float& f : g.feature) f = noise(rng);
  }
  pcl::KdTreeFLANN<GaussianPoint> tree;
  tree.setInputCloud(cloud);
  pcl::Indices neighbours(k + 1);
  std::vector<float> sq_dist(k + 1);
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    GaussianPoint& g = (*cloud)[i];
    const int found = tree.nearestKSearch(g, k + 1, neighbours, sq_dist);
    // The nearest hit is the point itself (distance 0); average the next k.
    double sum = 0.0;
    for (int j = 1; j < found; ++j) sum += std::sqrt(sq_dist[j]);
    const float mean = static_cast<float>(sum / std::max(1, found - 1));
    const float log_scale = std::log(std::max(mean, options.min_scale));
    for (float& s : g.scale) s = log_scale;
  }
  return *cloud;
}

}  // namespace gaussians
}  // namespace sadsplat
