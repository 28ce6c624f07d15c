#include "sadsplat/gaussians/initialization.h"

#include <pcl/kdtree/kdtree_flann.h>

#include <algorithm>
#include <array>
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

std::vector<io::ScenePoint> randomPointsInView(const std::vector<io::PinholeCamera>& cameras,
                                               int count, std::uint64_t seed) {
  if (cameras.empty()) {
    throw Error("<scene>", "training views", "at least one camera to place random points", "none");
  }
  if (count < 4) {
    throw Error("<config>", "init_random_count", "at least 4 points", std::to_string(count));
  }
  // Camera centres C = -R^T t.
  std::vector<std::array<double, 3>> centres;
  std::array<double, 3> mean{0, 0, 0};
  for (const auto& c : cameras) {
    const auto R = c.rotation();
    std::array<double, 3> C{};
    for (int i = 0; i < 3; ++i) {
      C[i] = -(R[0 * 3 + i] * c.tvec[0] + R[1 * 3 + i] * c.tvec[1] + R[2 * 3 + i] * c.tvec[2]);
      mean[i] += C[i] / cameras.size();
    }
    centres.push_back(C);
  }
  double radius = 0;
  for (const auto& C : centres) {
    radius = std::max(radius, std::sqrt(std::pow(C[0] - mean[0], 2) + std::pow(C[1] - mean[1], 2) +
                                        std::pow(C[2] - mean[2], 2)));
  }
  // Points along random rays of random cameras, at depths up to twice the box half-size around
  // the centres (1.5 x their spread, or 1 when they coincide): uniform draws in a box waste
  // almost every draw on space no two cameras share when the cameras look in one direction.
  const double half = radius > 1e-9 ? 1.5 * radius : 1.0;
  const double near = 0.05 * half, far = 2.0 * half;
  const std::size_t needed_views = std::min<std::size_t>(2, cameras.size());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<std::size_t> pick(0, cameras.size() - 1);
  std::uniform_int_distribution<int> colour(0, 255);
  std::vector<std::array<double, 9>> rotations;
  for (const auto& c : cameras) rotations.push_back(c.rotation());
  std::vector<io::ScenePoint> points;
  const std::int64_t max_draws = 200ll * count;
  for (std::int64_t draw = 0; draw < max_draws && static_cast<int>(points.size()) < count; ++draw) {
    const std::size_t i = pick(rng);
    const io::PinholeCamera& from = cameras[i];
    const auto& R = rotations[i];
    const double depth = near + (far - near) * unit(rng);
    const double xc = (unit(rng) * from.width - from.cx) / from.fx * depth;
    const double yc = (unit(rng) * from.height - from.cy) / from.fy * depth;
    // World point X = R^T (x_cam - t).
    const double d[3] = {xc - from.tvec[0], yc - from.tvec[1], depth - from.tvec[2]};
    std::array<double, 3> X{};
    for (int k = 0; k < 3; ++k)
      X[k] = R[0 * 3 + k] * d[0] + R[1 * 3 + k] * d[1] + R[2 * 3 + k] * d[2];
    std::size_t seen = 0;
    for (std::size_t j = 0; j < cameras.size() && seen < needed_views; ++j) {
      const auto& c = cameras[j];
      const auto& Rj = rotations[j];
      double x[3];
      for (int k = 0; k < 3; ++k) {
        x[k] = Rj[k * 3 + 0] * X[0] + Rj[k * 3 + 1] * X[1] + Rj[k * 3 + 2] * X[2] + c.tvec[k];
      }
      if (x[2] <= 1e-9) continue;
      const double u = c.fx * x[0] / x[2] + c.cx, v = c.fy * x[1] / x[2] + c.cy;
      if (u >= 0 && u < c.width && v >= 0 && v < c.height) ++seen;
    }
    if (seen < needed_views) continue;
    io::ScenePoint p;
    for (int k = 0; k < 3; ++k) p.xyz[k] = static_cast<float>(X[k]);
    for (auto& ch : p.rgb) ch = static_cast<std::uint8_t>(colour(rng));
    points.push_back(p);
  }
  if (points.size() < 4) {
    throw Error(
        "<scene>", "cameras",
        "views that overlap (random points seen by " + std::to_string(needed_views) + " cameras)",
        std::to_string(points.size()) + " such points in " + std::to_string(max_draws) + " draws");
  }
  return points;
}

bool initialisesRandomly(InitMode init, std::size_t num_points) {
  if (init == InitMode::kRandom) return true;
  if (init == InitMode::kAuto) return num_points < 4;
  if (num_points < 4) {
    throw Error("<scene>", "sparse points",
                "at least 4 points to initialise Gaussians (or --init random)",
                std::to_string(num_points));
  }
  return false;
}

}  // namespace gaussians
}  // namespace sadsplat
