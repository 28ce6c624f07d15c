#include "sadsplat/gaussians/view_coverage.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/raster_math.h"

namespace sadsplat {
namespace gaussians {
namespace {

// The world-to-camera rotation R ([3, 3], one row per camera axis) and translation t ([3]) of a
// camera, as double tensors: x_c = R x + t.
std::pair<at::Tensor, at::Tensor> cameraPose(const RasterCamera& c, const at::TensorOptions& opts) {
  const double q[4] = {c.qvec[0], c.qvec[1], c.qvec[2], c.qvec[3]};
  double R[9];
  raster::quatToRotation(q, R);
  return {at::tensor(std::vector<double>(R, R + 9), opts).view({3, 3}),
          at::tensor(std::vector<double>(c.tvec.begin(), c.tvec.end()), opts)};
}

// Where a camera sees world points (`m`, [N, 3] double): pixel coordinates, camera z, and
// whether each point lies beyond the near plane and inside the image.
struct Projection {
  at::Tensor u, v, z, seen;
};

Projection project(const at::Tensor& m, const RasterCamera& c) {
  const auto [R, t] = cameraPose(c, m.options());
  const at::Tensor cam = at::matmul(m, R.t()) + t;
  const at::Tensor x = cam.select(1, 0), y = cam.select(1, 1), z = cam.select(1, 2);
  const at::Tensor in_front = z > c.near_plane;
  const at::Tensor zs = at::where(in_front, z, at::ones_like(z));
  Projection p;
  p.u = c.fx * x / zs + c.cx;
  p.v = c.fy * y / zs + c.cy;
  p.z = z;
  p.seen = in_front & (p.u >= 0) & (p.u < c.width) & (p.v >= 0) & (p.v < c.height);
  return p;
}

}  // namespace

at::Tensor cameraDepths(const at::Tensor& points, const RasterCamera& camera) {
  return project(points.detach().to(at::kDouble), camera).z;
}

double sceneExtent(const std::vector<RasterCamera>& cameras) {
  if (cameras.empty()) return 1e-3;
  std::array<double, 3> mean{0, 0, 0};
  std::vector<std::array<double, 3>> centres;
  for (const RasterCamera& c : cameras) centres.push_back(c.centre());
  for (const auto& c : centres) {
    for (int k = 0; k < 3; ++k) mean[k] += c[k] / centres.size();
  }
  double radius = 0;
  for (const auto& c : centres) {
    radius = std::max(radius, std::sqrt(std::pow(c[0] - mean[0], 2) + std::pow(c[1] - mean[1], 2) +
                                        std::pow(c[2] - mean[2], 2)));
  }
  return std::max(1e-3, 1.1 * radius);
}

at::Tensor viewCounts(const at::Tensor& means, const std::vector<RasterCamera>& cameras) {
  if (means.dim() != 2 || means.size(1) != 3) {
    throw Error("<view coverage>", "means", "an [N, 3] tensor", std::to_string(means.dim()) + "-d");
  }
  const at::Tensor m = means.detach().to(at::kDouble);
  at::Tensor counts = at::zeros({means.size(0)}, means.options().dtype(at::kInt));
  for (const RasterCamera& c : cameras) counts += project(m, c).seen.to(at::kInt);
  return counts;
}

at::Tensor seenUnoccluded(const at::Tensor& points, const RasterCamera& camera,
                          const at::Tensor& depth, const at::Tensor& alpha,
                          double relative_tolerance) {
  if (points.dim() != 2 || points.size(1) != 3) {
    throw Error("<view coverage>", "points", "an [N, 3] tensor",
                std::to_string(points.dim()) + "-d");
  }
  const std::vector<std::int64_t> shape = {camera.height, camera.width};
  if (depth.sizes() != at::IntArrayRef(shape) || alpha.sizes() != at::IntArrayRef(shape)) {
    throw Error("<view coverage>", "depth / alpha",
                "[" + std::to_string(camera.height) + ", " + std::to_string(camera.width) +
                    "] images of the camera",
                "[" + std::to_string(depth.numel()) + "] and [" + std::to_string(alpha.numel()) +
                    "] values");
  }
  const Projection p = project(points.detach().to(at::kDouble), camera);
  const at::Tensor u = p.u.clamp(0, camera.width - 1).to(at::kLong);
  const at::Tensor v = p.v.clamp(0, camera.height - 1).to(at::kLong);
  const at::Tensor index = (v * camera.width + u).to(depth.device());
  const at::Tensor d = depth.detach().reshape(-1).to(at::kDouble).index_select(0, index);
  const at::Tensor a = alpha.detach().reshape(-1).index_select(0, index);
  const at::Tensor z = p.z.to(depth.device());
  const at::Tensor agrees = (d - z).abs() <= relative_tolerance * z.abs();
  return (p.seen.to(depth.device()) & agrees & (a >= 0.5)).to(points.device());
}

at::Tensor pixelViewCounts(const at::Tensor& depth, const at::Tensor& alpha,
                           const RasterCamera& camera, const std::vector<RasterCamera>& cameras,
                           double min_alpha, int stride) {
  const std::string what = "<view coverage>";
  if (camera.orthographic) {
    throw Error(what, "camera", "a pinhole camera (pixels back-project along rays)",
                "an orthographic one");
  }
  const std::vector<std::int64_t> shape = {camera.height, camera.width};
  if (depth.sizes() != at::IntArrayRef(shape) || alpha.sizes() != at::IntArrayRef(shape)) {
    throw Error(what, "depth / alpha",
                "[" + std::to_string(camera.height) + ", " + std::to_string(camera.width) +
                    "] images of the camera",
                "[" + std::to_string(depth.numel()) + "] and [" + std::to_string(alpha.numel()) +
                    "] values");
  }
  stride = std::max(1, stride);
  const auto opts = depth.options().dtype(at::kDouble);
  // One pixel of each stride x stride block (its centre, rounded down; inside the image for a
  // block the edge cuts) stands for the block.
  const std::int64_t first = (stride - 1) / 2;
  const auto lopts = opts.dtype(at::kLong);
  const at::Tensor cols =
      at::arange(0, camera.width, stride, lopts).add(first).clamp_max(camera.width - 1);
  const at::Tensor rows_idx =
      at::arange(0, camera.height, stride, lopts).add(first).clamp_max(camera.height - 1);
  const at::Tensor z =
      depth.detach().to(at::kDouble).index_select(0, rows_idx).index_select(1, cols);
  // Pixel centres at +0.5 (the rasterizer's convention), to camera coordinates at depth z.
  const at::Tensor u = cols.to(at::kDouble).add(0.5).view({1, -1});
  const at::Tensor v = rows_idx.to(at::kDouble).add(0.5).view({-1, 1});
  const at::Tensor cam =
      at::stack({(u - camera.cx) / camera.fx * z, (v - camera.cy) / camera.fy * z, z}, 2)
          .view({-1, 3});
  // World x = R^T (x_c - t): as rows, (x_c - t) R.
  const auto [R, t] = cameraPose(camera, opts);
  const at::Tensor world = at::matmul(cam - t, R);
  at::Tensor counts = viewCounts(world, cameras).view({rows_idx.size(0), cols.size(0)});
  if (stride > 1) {
    counts = counts.repeat_interleave(stride, 0)
                 .repeat_interleave(stride, 1)
                 .narrow(0, 0, camera.height)
                 .narrow(1, 0, camera.width)
                 .contiguous();
  }
  return at::where(alpha.detach() >= min_alpha, counts, at::zeros_like(counts));
}

at::Tensor sparsePointTensor(const io::Scene& scene) {
  if (scene.points.empty()) return at::Tensor();
  std::vector<float> xyz;
  xyz.reserve(3 * scene.points.size());
  for (const io::ScenePoint& p : scene.points) xyz.insert(xyz.end(), p.xyz.begin(), p.xyz.end());
  return at::tensor(xyz, at::kFloat).view({-1, 3});
}

at::Tensor sparseDepthImage(const at::Tensor& points, const RasterCamera& camera, int cell) {
  if (points.dim() != 2 || points.size(1) != 3) {
    throw Error("<view coverage>", "sparse points", "a [P, 3] tensor",
                std::to_string(points.dim()) + "-d");
  }
  cell = std::max(1, cell);
  const int W = camera.width, H = camera.height;
  const int cols = (W + cell - 1) / cell, rows = (H + cell - 1) / cell;
  const Projection p = project(points.detach().to(at::kCPU, at::kDouble), camera);
  const auto u = p.u.accessor<double, 1>(), v = p.v.accessor<double, 1>(),
             z = p.z.accessor<double, 1>();
  const auto seen = p.seen.accessor<bool, 1>();
  std::vector<std::vector<double>> depths(static_cast<std::size_t>(cols) * rows);
  for (std::int64_t i = 0; i < p.z.size(0); ++i) {
    if (!seen[i]) continue;
    depths[static_cast<std::size_t>(static_cast<int>(v[i]) / cell) * cols +
           static_cast<int>(u[i]) / cell]
        .push_back(z[i]);
  }
  std::vector<double> cell_depth(depths.size(), 0.0);
  std::vector<int> filled;
  for (std::size_t k = 0; k < depths.size(); ++k) {
    std::vector<double>& d = depths[k];
    if (d.empty()) continue;
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    cell_depth[k] = d[d.size() / 2];
    filled.push_back(static_cast<int>(k));
  }
  if (filled.empty()) return at::Tensor();
  for (std::size_t k = 0; k < depths.size(); ++k) {
    if (!depths[k].empty()) continue;
    const int r = static_cast<int>(k) / cols, c = static_cast<int>(k) % cols;
    int best = filled.front();
    long best_d2 = -1;
    for (int f : filled) {  // a few hundred blocks per view: the direct search is enough
      const long dr = f / cols - r, dc = f % cols - c, d2 = dr * dr + dc * dc;
      if (best_d2 < 0 || d2 < best_d2) best = f, best_d2 = d2;
    }
    cell_depth[k] = cell_depth[static_cast<std::size_t>(best)];
  }
  at::Tensor image = at::empty({H, W}, at::kFloat);
  float* out = image.data_ptr<float>();
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      out[static_cast<std::size_t>(y) * W + x] =
          static_cast<float>(cell_depth[static_cast<std::size_t>(y / cell) * cols + x / cell]);
    }
  }
  return image;
}

SparseDepthSamples visibleSparseDepths(const at::Tensor& points, const RasterCamera& camera,
                                       int cell, double relative_tolerance) {
  if (points.dim() != 2 || points.size(1) != 3) {
    throw Error("<view coverage>", "sparse points", "a [P, 3] tensor",
                std::to_string(points.dim()) + "-d");
  }
  cell = std::max(1, cell);
  const int W = camera.width;
  const int cols = (W + cell - 1) / cell, rows = (camera.height + cell - 1) / cell;
  const Projection p = project(points.detach().to(at::kCPU, at::kDouble), camera);
  const auto u = p.u.accessor<double, 1>(), v = p.v.accessor<double, 1>(),
             z = p.z.accessor<double, 1>();
  const auto seen = p.seen.accessor<bool, 1>();
  const auto blockOf = [&](std::int64_t i) {
    return static_cast<std::size_t>(static_cast<int>(v[i]) / cell) * cols +
           static_cast<int>(u[i]) / cell;
  };
  std::vector<double> nearest(static_cast<std::size_t>(cols) * rows,
                              std::numeric_limits<double>::infinity());
  for (std::int64_t i = 0; i < p.z.size(0); ++i) {
    if (seen[i]) nearest[blockOf(i)] = std::min(nearest[blockOf(i)], z[i]);
  }
  std::vector<std::int64_t> pixels;
  std::vector<float> depths;
  for (std::int64_t i = 0; i < p.z.size(0); ++i) {
    if (!seen[i] || z[i] - nearest[blockOf(i)] > relative_tolerance * z[i]) continue;
    pixels.push_back(static_cast<std::int64_t>(v[i]) * W + static_cast<std::int64_t>(u[i]));
    depths.push_back(static_cast<float>(z[i]));
  }
  SparseDepthSamples s;
  const auto n = static_cast<std::int64_t>(pixels.size());
  s.pixels = at::tensor(pixels, at::kLong).view({n});
  s.depths = at::tensor(depths, at::kFloat).view({n});
  return s;
}

at::Tensor floaterMask(const at::Tensor& means, const at::Tensor& log_scales,
                       const std::vector<RasterCamera>& cameras, int min_views, double max_scale) {
  at::Tensor floater = at::zeros({means.size(0)}, means.options().dtype(at::kBool));
  if (min_views > 0) floater = floater | (viewCounts(means, cameras) < min_views);
  if (max_scale > 0) {
    const at::Tensor largest = std::get<0>(log_scales.detach().max(1)).exp();
    floater = floater | (largest > max_scale);
  }
  return floater;
}

}  // namespace gaussians
}  // namespace sadsplat
