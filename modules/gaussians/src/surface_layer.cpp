#include "sadsplat/gaussians/surface_layer.h"

#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "raster_backend.h"
#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/raster_math.h"

namespace sadsplat {
namespace gaussians {
namespace {

// One Gaussian as the layer composites it: its splat (as the rasterizer projects it), the box
// where it can reach kMinAlpha, and the plane its density's maximum along the rays follows.
struct Splat {
  double mean2d[2];
  double conic[3];
  double opacity;
  double depth;       // camera z of the centre
  double slope[2];    // d(depth on the ray) / d(pixel x, y)
  double max_offset;  // 3 standard deviations in camera z
  // Pinhole: the centre in camera coordinates and the inverse camera-frame covariance (rows of
  // the symmetric 3 x 3: xx, xy, xz, yy, yz, zz), for the density's maximum along a ray.
  double centre[3];
  double precision[6];
  raster::AlphaEllipse<double> ellipse;
  int tx0, tx1, ty0, ty1;  // the rasterizer's tile rectangle [tx0, tx1) x [ty0, ty1)
  std::int64_t index;
};

at::Tensor cpuDouble(const at::Tensor& t) {
  return t.detach().to(at::kCPU, at::kDouble).contiguous();
}

void expectRows(const at::Tensor& t, const char* name, std::int64_t n, std::int64_t columns) {
  const bool ok = t.defined() && t.dim() == (columns > 0 ? 2 : 1) && t.size(0) == n &&
                  (columns <= 0 || t.size(1) == columns);
  if (!ok) {
    throw Error("<surface layer>", name,
                "[" + std::to_string(n) + (columns > 0 ? ", " + std::to_string(columns) : "") + "]",
                t.defined() ? std::to_string(t.dim()) + " dimensions" : "undefined");
  }
}

// Pinhole: camera z of the density's maximum along the ray through pixel (fx, fy), minus the
// centre's; 0 where the ray runs parallel to a flat Gaussian (d^T P d vanishes).
double rayOffset(const Splat& s, const raster::Camera<double>& cam, double fx, double fy) {
  const double d[3] = {(fx - cam.cx) / cam.fx, (fy - cam.cy) / cam.fy, 1.0};
  const double* P = s.precision;
  const double Pd[3] = {P[0] * d[0] + P[1] * d[1] + P[2] * d[2],
                        P[1] * d[0] + P[3] * d[1] + P[4] * d[2],
                        P[2] * d[0] + P[4] * d[1] + P[5] * d[2]};
  const double dPd = Pd[0] * d[0] + Pd[1] * d[1] + Pd[2] * d[2];
  const double dPp = Pd[0] * s.centre[0] + Pd[1] * s.centre[1] + Pd[2] * s.centre[2];
  if (!(dPd > 0) || !std::isfinite(dPp / dPd)) return 0.0;
  return dPp / dPd - s.depth;
}

// The Gaussians' splats through `camera` in the rasterizer's compositing order, after checking
// the shapes; `level` is checked here too.
std::vector<Splat> sortedSplats(const GaussianParams& g, const RasterCamera& camera, double level,
                                const raster::Camera<double>& cam) {
  if (!(level > raster::kMinTransmittance && level < 1)) {
    throw Error("<surface layer>", "level", "a transmittance in (1e-4, 1)", std::to_string(level));
  }
  if (camera.width <= 0 || camera.height <= 0) {
    throw Error("<surface layer>", "camera size", "width and height > 0",
                std::to_string(camera.width) + " x " + std::to_string(camera.height));
  }
  if (!g.means.defined()) throw Error("<surface layer>", "means", "[N, 3]", "undefined");
  const std::int64_t n = g.means.size(0);
  expectRows(g.means, "means", n, 3);
  expectRows(g.quats, "quats", n, 4);
  expectRows(g.log_scales, "log_scales", n, 3);
  expectRows(g.opacity_logits, "opacity_logits", n, 0);
  if (g.opacity_gate.defined()) expectRows(g.opacity_gate, "opacity_gate", n, 0);
  if (g.features.defined() && g.features.size(1) > 0) {
    expectRows(g.features, "features", n, g.features.size(1));
  }

  const at::Tensor means = cpuDouble(g.means), quats = cpuDouble(g.quats),
                   log_scales = cpuDouble(g.log_scales);
  at::Tensor opacity = at::sigmoid(cpuDouble(g.opacity_logits));
  if (g.opacity_gate.defined()) opacity = opacity * cpuDouble(g.opacity_gate);
  opacity = opacity.contiguous();
  const double* pm = means.data_ptr<double>();
  const double* pq = quats.data_ptr<double>();
  const double* ps = log_scales.data_ptr<double>();
  const double* po = opacity.data_ptr<double>();
  const int W = camera.width, H = camera.height;
  const auto [tiles_x, tiles_y] = raster::tileGrid(W, H);
  std::vector<Splat> splats;
  splats.reserve(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    raster::Projected<double> p;
    if (!raster::projectGaussian(pm + 3 * i, pq + 4 * i, ps + 3 * i, cam, &p)) continue;
    // Binned as the rasterizer bins (raster_cpu.cpp): every pixel of a tile it meets is
    // composited, also beyond its 3-sigma radius.
    Splat s;
    if (!raster::alphaEllipse(p.mean2d, p.conic, po[i], &s.ellipse)) continue;
    int rx = 0, ry = 0;
    raster::alphaBox(p.radius, s.ellipse, &rx, &ry);
    if (rx <= 0) continue;
    raster::tileRect(p.mean2d, rx, ry, tiles_x, tiles_y, &s.tx0, &s.ty0, &s.tx1, &s.ty1);
    if (s.tx0 >= s.tx1 || s.ty0 >= s.ty1) continue;
    s.mean2d[0] = p.mean2d[0], s.mean2d[1] = p.mean2d[1];
    for (int k = 0; k < 3; ++k) s.conic[k] = p.conic[k];
    s.opacity = po[i];
    // The rasterizer orders by the centre's depth in float, then by index.
    s.depth = p.depth;
    s.index = i;
    // Camera-frame covariance V = R S R^T; along a ray (x, y fixed) the density peaks at the
    // conditional mean z + V_zxy V_xy^-1 (x - x0, y - y0). V_xy gets the rasterizer's low-pass
    // dilation (0.3 px^2, in world units) so that a Gaussian seen edge-on keeps a finite slope.
    raster::EwaTerms<double> e;
    raster::ewaTerms(pm + 3 * i, pq + 4 * i, ps + 3 * i, cam, &e);
    double V[9];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        double v = 0;
        for (int k = 0; k < 3; ++k) {
          for (int l = 0; l < 3; ++l) v += cam.R[3 * r + k] * e.S[3 * k + l] * cam.R[3 * c + l];
        }
        V[3 * r + c] = v;
      }
    }
    const double dil_x = raster::kDilation / (cam.fx * cam.fx),
                 dil_y = raster::kDilation / (cam.fy * cam.fy);
    const double a = V[0] + dil_x, b = V[1], c = V[4] + dil_y, det = a * c - b * b;
    const double kx = det > 0 ? (V[6] * c - V[7] * b) / det : 0.0,
                 ky = det > 0 ? (V[7] * a - V[6] * b) / det : 0.0;
    s.slope[0] = kx / cam.fx;  // per pixel: world x = (pixel - cx) / fx
    s.slope[1] = ky / cam.fy;
    s.max_offset = 3 * std::sqrt(std::max(0.0, V[8]));
    if (!cam.orthographic) {
      // The ray t (x', y', 1) of a pinhole pixel meets the density's maximum at
      // t = d^T P p / d^T P d, P = (R Rq) diag(1/s^2) (R Rq)^T the inverse covariance (exact from
      // the scales: a flat Gaussian's P is its plane, and t the ray's crossing of it).
      double Rc[9];  // camera-frame rotation of the Gaussian's axes
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          Rc[3 * r + c] = cam.R[3 * r] * e.Rq[c] + cam.R[3 * r + 1] * e.Rq[3 + c] +
                          cam.R[3 * r + 2] * e.Rq[6 + c];
        }
      }
      const int rows[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
      for (int k = 0; k < 6; ++k) {
        double v = 0;
        for (int a = 0; a < 3; ++a) {
          const double inv = 1 / std::max(e.s[a] * e.s[a], 1e-300);
          v += Rc[3 * rows[k][0] + a] * Rc[3 * rows[k][1] + a] * inv;
        }
        s.precision[k] = v;
      }
      for (int k = 0; k < 3; ++k) s.centre[k] = e.p[k];
    }
    splats.push_back(s);
  }
  std::stable_sort(splats.begin(), splats.end(), [](const Splat& l, const Splat& r) {
    const float dl = static_cast<float>(l.depth), dr = static_cast<float>(r.depth);
    return dl < dr;  // stable: equal float depths keep index order, as the rasterizer's sort
  });
  return splats;
}

// Composites the sorted splats over the pixels of tile row `ty` in the rasterizer's order, each
// pixel until its transmittance falls below `level`: blend(k, s, w) for every blend (k: the
// pixel's index in the row, w: the blend weight), then reach(k, s, fx, fy) where the fall below
// `level` happens (s: the splat that takes it there, fx, fy: the pixel's centre).
template <typename Blend, typename Reach>
void compositeTileRow(const std::vector<Splat>& splats, int ty, int W, int H, double level,
                      Blend&& blend, Reach&& reach) {
  const int r0 = ty * raster::kTileSize, r1 = std::min(H, r0 + raster::kTileSize);
  const std::size_t pixels = static_cast<std::size_t>(r1 - r0) * W;
  std::vector<double> trans(pixels, 1.0);
  std::vector<char> done(pixels, 0);
  for (const Splat& s : splats) {
    if (ty < s.ty0 || ty >= s.ty1) continue;
    for (int tx = s.tx0; tx < s.tx1; ++tx) {
      if (!raster::alphaEllipseMeetsTile(s.ellipse, tx, ty)) continue;
      const int c0 = tx * raster::kTileSize, c1 = std::min(W, c0 + raster::kTileSize);
      for (int py = r0; py < r1; ++py) {
        for (int px = c0; px < c1; ++px) {
          const std::size_t k = static_cast<std::size_t>(py - r0) * W + px;
          if (done[k]) continue;
          const double fx = px + 0.5, fy = py + 0.5;
          double G = 0;
          bool clamped = false;
          const double alpha =
              raster::pixelAlpha(s.mean2d, s.conic, s.opacity, fx, fy, &G, &clamped);
          if (alpha == 0) continue;
          const double next = trans[k] * (1 - alpha);
          if (next < raster::kMinTransmittance) {  // the rasterizer stops before it
            done[k] = 1;
            continue;
          }
          blend(k, s, alpha * trans[k]);
          trans[k] = next;
          if (next < level) {
            done[k] = 1;
            reach(k, s, fx, fy);
          }
        }
      }
    }
  }
}

// Camera z of the surface at pixel (fx, fy) of the splat that takes the transmittance there.
double surfaceDepth(const Splat& s, const raster::Camera<double>& cam, double fx, double fy) {
  const double off = cam.orthographic
                         ? s.slope[0] * (fx - s.mean2d[0]) + s.slope[1] * (fy - s.mean2d[1])
                         : rayOffset(s, cam, fx, fy);
  return s.depth + std::max(-s.max_offset, std::min(s.max_offset, off));
}

}  // namespace

SurfaceLayer renderSurfaceLayer(const GaussianParams& g, const RasterCamera& camera, double level) {
  const raster::Camera<double> cam = raster::toCamera<double>(raster::cameraParams(camera));
  const std::vector<Splat> splats = sortedSplats(g, camera, level, cam);
  const std::int64_t C = g.features.defined() ? g.features.size(1) : 0;
  const at::Tensor features = C > 0 ? cpuDouble(g.features) : at::Tensor();
  const double* pf = C > 0 ? features.data_ptr<double>() : nullptr;
  const int W = camera.width, H = camera.height;
  const int tiles_y = raster::tileGrid(W, H).second;

  SurfaceLayer out;
  const auto f32 = at::TensorOptions().dtype(at::kFloat);
  out.reached = at::zeros({H, W}, at::TensorOptions().dtype(at::kBool));
  out.depth = at::zeros({H, W}, f32);
  out.weight = at::zeros({H, W}, f32);
  out.features = at::zeros({H, W, C}, f32);
  bool* reached = out.reached.data_ptr<bool>();
  float* depth = out.depth.data_ptr<float>();
  float* weight = out.weight.data_ptr<float>();
  float* feat = out.features.data_ptr<float>();

  // One row of tiles per task: each walks the whole sorted list (the order is per pixel) and
  // touches only its own pixels, so the result does not depend on the thread count.
  at::parallel_for(0, tiles_y, 1, [&](std::int64_t b0, std::int64_t b1) {
    for (std::int64_t b = b0; b < b1; ++b) {
      const int ty = static_cast<int>(b);
      const int r0 = ty * raster::kTileSize, r1 = std::min(H, r0 + raster::kTileSize);
      const std::size_t pixels = static_cast<std::size_t>(r1 - r0) * W;
      std::vector<double> wsum(pixels, 0.0), acc(pixels * static_cast<std::size_t>(C), 0.0);
      const auto blend = [&](std::size_t k, const Splat& s, double w) {
        wsum[k] += w;
        if (C > 0) {
          const double* f = pf + s.index * C;
          double* a = acc.data() + k * C;
          for (std::int64_t ch = 0; ch < C; ++ch) a[ch] += w * f[ch];
        }
      };
      const auto reach = [&](std::size_t k, const Splat& s, double fx, double fy) {
        const std::size_t o = static_cast<std::size_t>(r0) * W + k;
        reached[o] = true;
        depth[o] = static_cast<float>(surfaceDepth(s, cam, fx, fy));
      };
      compositeTileRow(splats, ty, W, H, level, blend, reach);
      for (std::size_t k = 0; k < pixels; ++k) {
        const std::size_t o = static_cast<std::size_t>(r0) * W + k;
        weight[o] = static_cast<float>(wsum[k]);
        if (C > 0 && wsum[k] > 0) {
          for (std::int64_t ch = 0; ch < C; ++ch) {
            feat[o * C + ch] = static_cast<float>(acc[k * C + ch] / wsum[k]);
          }
        }
      }
    }
  });
  return out;
}

at::Tensor surfaceGapSums(const GaussianParams& g, const RasterCamera& camera, double level) {
  const raster::Camera<double> cam = raster::toCamera<double>(raster::cameraParams(camera));
  const std::vector<Splat> splats = sortedSplats(g, camera, level, cam);
  const int W = camera.width, H = camera.height;
  const int tiles_y = raster::tileGrid(W, H).second;
  // Per row of tiles, per splat it blends into a pixel that reaches the surface: the sums of w
  // and w (D - z). Rows are summed in order afterwards, so the result does not depend on the
  // threads.
  struct RowSums {
    std::vector<std::int64_t> index;
    std::vector<double> weight, weighted_gap;
  };
  std::vector<RowSums> rows(static_cast<std::size_t>(tiles_y));
  at::parallel_for(0, tiles_y, 1, [&](std::int64_t b0, std::int64_t b1) {
    for (std::int64_t b = b0; b < b1; ++b) {
      const int ty = static_cast<int>(b);
      const int r0 = ty * raster::kTileSize, r1 = std::min(H, r0 + raster::kTileSize);
      const std::size_t pixels = static_cast<std::size_t>(r1 - r0) * W;
      // Every blend of the row, resolved once its pixel's surface depth is known.
      struct Blend {
        std::uint32_t pixel;
        std::uint32_t splat;  // position in `splats`
        double w;
      };
      std::vector<Blend> blends;
      std::vector<double> surface(pixels, std::numeric_limits<double>::quiet_NaN());
      const Splat* first = splats.data();
      compositeTileRow(
          splats, ty, W, H, level,
          [&](std::size_t k, const Splat& s, double w) {
            blends.push_back(
                {static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(&s - first), w});
          },
          [&](std::size_t k, const Splat& s, double fx, double fy) {
            surface[k] = surfaceDepth(s, cam, fx, fy);
          });
      // The blends come splat by splat in order: one row entry per splat.
      RowSums& out = rows[static_cast<std::size_t>(b)];
      std::int64_t last = -1;
      for (const Blend& e : blends) {
        const double d = surface[e.pixel];
        if (std::isnan(d)) continue;  // the pixel shows no surface
        if (static_cast<std::int64_t>(e.splat) != last) {
          last = e.splat;
          out.index.push_back(splats[e.splat].index);
          out.weight.push_back(0);
          out.weighted_gap.push_back(0);
        }
        out.weight.back() += e.w;
        out.weighted_gap.back() += e.w * (d - splats[e.splat].depth);
      }
    }
  });
  const std::int64_t n = g.means.size(0);
  at::Tensor sums = at::zeros({n, 2}, at::TensorOptions().dtype(at::kDouble));
  double* ps = sums.data_ptr<double>();
  for (const RowSums& row : rows) {
    for (std::size_t k = 0; k < row.index.size(); ++k) {
      const std::int64_t i = row.index[k];
      ps[2 * i] += row.weight[k];
      ps[2 * i + 1] += row.weighted_gap[k];
    }
  }
  return sums;
}

}  // namespace gaussians
}  // namespace sadsplat
