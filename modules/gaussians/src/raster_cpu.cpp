// The CPU backend of the rasterizer: the reference for correctness. Multi-threaded over
// Gaussians (projection) and tiles (rasterization) with at::parallel_for; templated on the
// scalar type so gradient checks can run in double.
#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "raster_backend.h"
#include "sadsplat/gaussians/raster_math.h"
#include "sadsplat/gaussians/step_profile.h"

namespace sadsplat {
namespace gaussians {
namespace raster {
namespace {

// Grain sizes for at::parallel_for.
constexpr int64_t kGaussianGrain = 2048;

}  // namespace

ProjectionResult projectForwardCpu(const at::Tensor& means, const at::Tensor& quats,
                                   const at::Tensor& log_scales, const CameraParams& cam) {
  const int64_t n = means.size(0);
  ProjectionResult out;
  out.means2d = at::zeros({n, 2}, means.options());
  out.conics = at::zeros({n, 3}, means.options());
  out.depths = at::zeros({n}, means.options());
  out.radii = at::zeros({n}, means.options().dtype(at::kInt));
  AT_DISPATCH_FLOATING_TYPES(means.scalar_type(), "projectForwardCpu", [&] {
    const Camera<scalar_t> c = toCamera<scalar_t>(cam);
    const scalar_t* m = means.data_ptr<scalar_t>();
    const scalar_t* q = quats.data_ptr<scalar_t>();
    const scalar_t* s = log_scales.data_ptr<scalar_t>();
    scalar_t* m2 = out.means2d.data_ptr<scalar_t>();
    scalar_t* co = out.conics.data_ptr<scalar_t>();
    scalar_t* d = out.depths.data_ptr<scalar_t>();
    int* r = out.radii.data_ptr<int>();
    at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        Projected<scalar_t> p;
        if (!projectGaussian(m + 3 * i, q + 4 * i, s + 3 * i, c, &p)) continue;
        m2[2 * i] = p.mean2d[0];
        m2[2 * i + 1] = p.mean2d[1];
        for (int k = 0; k < 3; ++k) co[3 * i + k] = p.conic[k];
        d[i] = p.depth;
        r[i] = p.radius;
      }
    });
  });
  return out;
}

ProjectionGrads projectBackwardCpu(const at::Tensor& means, const at::Tensor& quats,
                                   const at::Tensor& log_scales, const at::Tensor& radii,
                                   const CameraParams& cam, const at::Tensor& g_means2d,
                                   const at::Tensor& g_conics, const at::Tensor& g_depths) {
  const int64_t n = means.size(0);
  ProjectionGrads g;
  g.means = at::zeros_like(means);
  g.quats = at::zeros_like(quats);
  g.log_scales = at::zeros_like(log_scales);
  AT_DISPATCH_FLOATING_TYPES(means.scalar_type(), "projectBackwardCpu", [&] {
    const Camera<scalar_t> c = toCamera<scalar_t>(cam);
    const scalar_t* m = means.data_ptr<scalar_t>();
    const scalar_t* q = quats.data_ptr<scalar_t>();
    const scalar_t* s = log_scales.data_ptr<scalar_t>();
    const int* r = radii.data_ptr<int>();
    const scalar_t* gm2 = g_means2d.data_ptr<scalar_t>();
    const scalar_t* gco = g_conics.data_ptr<scalar_t>();
    const scalar_t* gd = g_depths.data_ptr<scalar_t>();
    scalar_t* gm = g.means.data_ptr<scalar_t>();
    scalar_t* gq = g.quats.data_ptr<scalar_t>();
    scalar_t* gs = g.log_scales.data_ptr<scalar_t>();
    at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        if (r[i] <= 0) continue;
        projectGaussianBackward(m + 3 * i, q + 4 * i, s + 3 * i, c, gm2 + 2 * i, gco + 3 * i, gd[i],
                                gm + 3 * i, gq + 4 * i, gs + 3 * i);
      }
    });
  });
  return g;
}

at::Tensor shForwardCpu(const at::Tensor& sh, const at::Tensor& means,
                        const std::array<double, 3>& campos, int degree) {
  const int64_t n = means.size(0), K = sh.size(1);
  at::Tensor colors = at::empty({n, 3}, means.options());
  AT_DISPATCH_FLOATING_TYPES(means.scalar_type(), "shForwardCpu", [&] {
    const scalar_t cam[3] = {scalar_t(campos[0]), scalar_t(campos[1]), scalar_t(campos[2])};
    const scalar_t* s = sh.data_ptr<scalar_t>();
    const scalar_t* m = means.data_ptr<scalar_t>();
    scalar_t* c = colors.data_ptr<scalar_t>();
    at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i)
        shColor(s + i * K * 3, degree, m + 3 * i, cam, c + 3 * i);
    });
  });
  return colors;
}

std::pair<at::Tensor, at::Tensor> shBackwardCpu(const at::Tensor& sh, const at::Tensor& means,
                                                const std::array<double, 3>& campos, int degree,
                                                const at::Tensor& g_colors) {
  const int64_t n = means.size(0), K = sh.size(1);
  at::Tensor g_sh = at::zeros_like(sh), g_means = at::zeros_like(means);
  AT_DISPATCH_FLOATING_TYPES(means.scalar_type(), "shBackwardCpu", [&] {
    const scalar_t cam[3] = {scalar_t(campos[0]), scalar_t(campos[1]), scalar_t(campos[2])};
    const scalar_t* s = sh.data_ptr<scalar_t>();
    const scalar_t* m = means.data_ptr<scalar_t>();
    const scalar_t* gc = g_colors.data_ptr<scalar_t>();
    scalar_t* gs = g_sh.data_ptr<scalar_t>();
    scalar_t* gm = g_means.data_ptr<scalar_t>();
    at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        shColorBackward(s + i * K * 3, degree, m + 3 * i, cam, gc + 3 * i, gs + i * K * 3,
                        gm + 3 * i);
      }
    });
  });
  return {g_sh, g_means};
}

namespace {

// Per-tile lists sorted by (depth, id): the same order the CUDA backend's stable sort gives.
template <typename T>
Binning binGaussians(const T* means2d, const T* conics, const int* radii, const T* opacities,
                     const T* depths, int64_t n, int width, int height) {
  const ScopedPhase phase("binning");
  const auto [tiles_x, tiles_y] = tileGrid(width, height);
  const int num_tiles = tiles_x * tiles_y;
  std::vector<std::vector<int>> lists(num_tiles);
  for (int64_t i = 0; i < n; ++i) {
    int rx, ry;
    alphaBox(radii[i], opacities[i], conics + 3 * i, &rx, &ry);
    if (rx <= 0) continue;
    int x0, y0, x1, y1;
    tileRect(means2d + 2 * i, rx, ry, tiles_x, tiles_y, &x0, &y0, &x1, &y1);
    for (int ty = y0; ty < y1; ++ty) {
      for (int tx = x0; tx < x1; ++tx) lists[ty * tiles_x + tx].push_back(static_cast<int>(i));
    }
  }
  Binning b;
  b.tile_ranges = at::zeros({num_tiles, 2}, at::TensorOptions().dtype(at::kInt));
  int* ranges = b.tile_ranges.data_ptr<int>();
  int64_t total = 0;
  for (int t = 0; t < num_tiles; ++t) total += static_cast<int64_t>(lists[t].size());
  b.gaussian_ids = at::empty({total}, at::TensorOptions().dtype(at::kInt));
  int* ids = b.gaussian_ids.data_ptr<int>();
  at::parallel_for(0, num_tiles, 16, [&](int64_t begin, int64_t end) {
    for (int64_t t = begin; t < end; ++t) {
      auto& list = lists[t];
      // Sorting by float depth, ties by id, matches the CUDA key (depth bits of a float).
      std::stable_sort(list.begin(), list.end(), [&](int a, int c) {
        return static_cast<float>(depths[a]) < static_cast<float>(depths[c]);
      });
    }
  });
  int offset = 0;
  for (int t = 0; t < num_tiles; ++t) {
    ranges[2 * t] = offset;
    std::copy(lists[t].begin(), lists[t].end(), ids + offset);
    offset += static_cast<int>(lists[t].size());
    ranges[2 * t + 1] = offset;
  }
  return b;
}

// Below this power a Gaussian's alpha is certainly under kMinAlpha, so pixelAlpha (and its exp)
// can be skipped; the 1e-3 margin leaves every borderline case to pixelAlpha itself, so results
// are exactly those of the CUDA backend's unconditional calls.
template <typename T>
std::vector<T> skipThresholds(const T* opacities, int64_t n) {
  std::vector<T> thresholds(static_cast<std::size_t>(n));
  for (int64_t i = 0; i < n; ++i) {
    thresholds[i] = opacities[i] > T(0) ? std::log(T(kMinAlpha) / opacities[i]) - T(1e-3)
                                        : std::numeric_limits<T>::infinity();
  }
  return thresholds;
}

// Calls visit(px, py) for every pixel of tile (tx, ty) inside the image, row by row.
template <typename Visit>
inline void forEachTilePixel(int tx, int ty, int width, int height, Visit&& visit) {
  const int y_end = std::min(height, (ty + 1) * kTileSize);
  const int x_end = std::min(width, (tx + 1) * kTileSize);
  for (int py = ty * kTileSize; py < y_end; ++py) {
    for (int px = tx * kTileSize; px < x_end; ++px) visit(px, py);
  }
}

// One Gaussian of a tile's list, gathered: what a pixel needs to decide on it and blend it.
template <typename T>
struct PackedGaussian {
  T mean2d[2];
  T conic[3];
  T opacity;
  T skip;  // skipThresholds
};

// A tile's Gaussians copied front to back into contiguous arrays (values as [L, D]): every pixel
// of the tile walks the same list, so gathering it once per tile turns 256 indirect, scattered
// reads per Gaussian into one. The arithmetic per pixel is unchanged.
template <typename T>
struct TileList {
  std::vector<PackedGaussian<T>> gaussians;
  std::vector<T> values;
  const int* ids = nullptr;  // into the binning's gaussian_ids

  int size() const { return static_cast<int>(gaussians.size()); }

  void gather(const int* tile_ids, int count, const T* means2d, const T* conics, const T* opacities,
              const T* skip, const T* all_values, int64_t D) {
    ids = tile_ids;
    gaussians.resize(static_cast<std::size_t>(count));
    values.resize(static_cast<std::size_t>(count * D));
    for (int j = 0; j < count; ++j) {
      const int g = tile_ids[j];
      PackedGaussian<T>& p = gaussians[j];
      p.mean2d[0] = means2d[2 * g];
      p.mean2d[1] = means2d[2 * g + 1];
      for (int k = 0; k < 3; ++k) p.conic[k] = conics[3 * g + k];
      p.opacity = opacities[g];
      p.skip = skip[g];
      std::copy(all_values + g * D, all_values + (g + 1) * D, values.begin() + j * D);
    }
  }
};

// Blends one tile of the forward pass. kD > 0: the channel count as a compile-time constant (the
// RGB-only renders); 0: `dynamic_d` channels.
template <int kD, typename T>
void forwardTile(const TileList<T>& list, int64_t dynamic_d, int tx, int ty, int width, int height,
                 T* accum, T* img, T* alpha_out, int* last_out) {
  const int64_t D = kD > 0 ? kD : dynamic_d;
  const PackedGaussian<T>* pg = list.gaussians.data();
  const T* val = list.values.data();
  const int count = list.size();
  forEachTilePixel(tx, ty, width, height, [&](int px, int py) {
    const T fx = T(px) + T(0.5), fy = T(py) + T(0.5);
    std::fill(accum, accum + D, T(0));
    T trans = T(1);
    int last = 0;
    for (int j = 0; j < count; ++j) {
      const PackedGaussian<T>& p = pg[j];
      if (gaussianPower(p.conic, p.mean2d[0] - fx, p.mean2d[1] - fy) < p.skip) continue;
      T G;
      bool clamped;
      const T alpha = pixelAlpha(p.mean2d, p.conic, p.opacity, fx, fy, &G, &clamped);
      if (alpha == T(0)) continue;
      const T next = trans * (T(1) - alpha);
      if (next < T(kMinTransmittance)) break;
      const T w = alpha * trans;
      const T* v = val + j * D;
      for (int64_t ch = 0; ch < D; ++ch) accum[ch] += w * v[ch];
      trans = next;
      last = j + 1;
    }
    const int64_t pix = static_cast<int64_t>(py) * width + px;
    std::copy(accum, accum + D, img + pix * D);
    alpha_out[pix] = T(1) - trans;
    last_out[pix] = last;
  });
}

// The backward of one tile: gradients of the tile's Gaussians, in list order, into `grads`
// ([L, 6 + D]: mean2d, conic, opacity, values), which the caller has zeroed.
template <int kD, typename T>
void backwardTile(const TileList<T>& list, int64_t dynamic_d, int tx, int ty, int width, int height,
                  const T* gimg, const T* galpha, const T* alpha_fwd, const int* last_fwd, T* accum,
                  T* last_value, T* grads) {
  const int64_t D = kD > 0 ? kD : dynamic_d;
  const int64_t row = 6 + D;
  const PackedGaussian<T>* pg = list.gaussians.data();
  const T* val = list.values.data();
  forEachTilePixel(tx, ty, width, height, [&](int px, int py) {
    const int64_t pix = static_cast<int64_t>(py) * width + px;
    const T fx = T(px) + T(0.5), fy = T(py) + T(0.5);
    const T final_trans = T(1) - alpha_fwd[pix];
    const T* gpix = gimg + pix * D;
    T trans = final_trans;
    std::fill(accum, accum + D, T(0));
    std::fill(last_value, last_value + D, T(0));
    T last_alpha = T(0);
    for (int j = last_fwd[pix] - 1; j >= 0; --j) {
      const PackedGaussian<T>& p = pg[j];
      if (gaussianPower(p.conic, p.mean2d[0] - fx, p.mean2d[1] - fy) < p.skip) continue;
      T G;
      bool clamped;
      const T alpha = pixelAlpha(p.mean2d, p.conic, p.opacity, fx, fy, &G, &clamped);
      if (alpha == T(0)) continue;
      trans = trans / (T(1) - alpha);
      const T w = alpha * trans;
      T* gb = grads + j * row;
      const T* v = val + j * D;
      T g_a = T(0);
      for (int64_t ch = 0; ch < D; ++ch) {
        accum[ch] = last_alpha * last_value[ch] + (T(1) - last_alpha) * accum[ch];
        last_value[ch] = v[ch];
        g_a += (v[ch] - accum[ch]) * gpix[ch];
        gb[6 + ch] += w * gpix[ch];
      }
      g_a *= trans;
      g_a += galpha[pix] * final_trans / (T(1) - alpha);
      last_alpha = alpha;
      pixelAlphaBackward(p.mean2d, p.conic, p.opacity, fx, fy, G, clamped, g_a, gb, gb + 2, gb + 5);
    }
  });
}

}  // namespace

RasterResult rasterizeForwardCpu(const at::Tensor& means2d, const at::Tensor& conics,
                                 const at::Tensor& opacities, const at::Tensor& values,
                                 const at::Tensor& radii, const at::Tensor& depths, int width,
                                 int height) {
  const int64_t n = means2d.size(0);
  const int64_t D = values.size(1);
  RasterResult out;
  out.image = at::zeros({height, width, D}, values.options());
  out.alpha = at::zeros({height, width}, values.options());
  out.last = at::zeros({height, width}, values.options().dtype(at::kInt));
  AT_DISPATCH_FLOATING_TYPES(means2d.scalar_type(), "rasterizeForwardCpu", [&] {
    using T = scalar_t;
    const T* m2 = means2d.data_ptr<T>();
    const T* co = conics.data_ptr<T>();
    const T* op = opacities.data_ptr<T>();
    const T* val = values.data_ptr<T>();
    out.binning =
        binGaussians(m2, co, radii.data_ptr<int>(), op, depths.data_ptr<T>(), n, width, height);
    const int* ranges = out.binning.tile_ranges.data_ptr<int>();
    const int* ids = out.binning.gaussian_ids.data_ptr<int>();
    T* img = out.image.data_ptr<T>();
    T* alpha_out = out.alpha.data_ptr<T>();
    int* last_out = out.last.data_ptr<int>();
    const std::vector<T> skip = skipThresholds(op, n);
    const int tiles_x = tileGrid(width, height).first;
    const int num_tiles = static_cast<int>(out.binning.tile_ranges.size(0));
    at::parallel_for(0, num_tiles, 1, [&](int64_t begin, int64_t end) {
      std::vector<T> accum(static_cast<std::size_t>(D));
      TileList<T> list;
      for (int64_t tile = begin; tile < end; ++tile) {
        const int tx = static_cast<int>(tile % tiles_x), ty = static_cast<int>(tile / tiles_x);
        const int start = ranges[2 * tile], stop = ranges[2 * tile + 1];
        list.gather(ids + start, stop - start, m2, co, op, skip.data(), val, D);
        if (D == 3) {
          forwardTile<3>(list, D, tx, ty, width, height, accum.data(), img, alpha_out, last_out);
        } else {
          forwardTile<0>(list, D, tx, ty, width, height, accum.data(), img, alpha_out, last_out);
        }
      }
    });
  });
  return out;
}

RasterGrads rasterizeBackwardCpu(const at::Tensor& means2d, const at::Tensor& conics,
                                 const at::Tensor& opacities, const at::Tensor& values,
                                 const RasterResult& fwd, const at::Tensor& g_image,
                                 const at::Tensor& g_alpha) {
  const int64_t n = means2d.size(0);
  const int64_t D = values.size(1);
  const int height = static_cast<int>(fwd.alpha.size(0));
  const int width = static_cast<int>(fwd.alpha.size(1));
  // One gradient buffer per thread (tiles share Gaussians), summed at the end; each tile sums
  // into its own list-ordered rows first and adds them to its thread's buffer once. Row layout:
  // mean2d (2), conic (3), opacity (1), values (D).
  const int64_t row = 6 + D;
  const int threads = at::get_num_threads();
  at::Tensor buffers = at::zeros({threads, n, row}, values.options());
  AT_DISPATCH_FLOATING_TYPES(means2d.scalar_type(), "rasterizeBackwardCpu", [&] {
    using T = scalar_t;
    const T* m2 = means2d.data_ptr<T>();
    const T* co = conics.data_ptr<T>();
    const T* op = opacities.data_ptr<T>();
    const T* val = values.data_ptr<T>();
    const T* gimg = g_image.data_ptr<T>();
    const T* galpha = g_alpha.data_ptr<T>();
    const T* alpha_fwd = fwd.alpha.data_ptr<T>();
    const int* last_fwd = fwd.last.data_ptr<int>();
    const int* ranges = fwd.binning.tile_ranges.data_ptr<int>();
    const int* ids = fwd.binning.gaussian_ids.data_ptr<int>();
    T* buf_base = buffers.data_ptr<T>();
    const std::vector<T> skip = skipThresholds(op, n);
    const int tiles_x = tileGrid(width, height).first;
    const int num_tiles = static_cast<int>(fwd.binning.tile_ranges.size(0));
    at::parallel_for(0, num_tiles, 1, [&](int64_t begin, int64_t end) {
      T* buf = buf_base + static_cast<int64_t>(at::get_thread_num()) * n * row;
      std::vector<T> accum(static_cast<std::size_t>(D)), last_value(static_cast<std::size_t>(D));
      std::vector<T> grads;
      TileList<T> list;
      for (int64_t tile = begin; tile < end; ++tile) {
        const int tx = static_cast<int>(tile % tiles_x), ty = static_cast<int>(tile / tiles_x);
        const int start = ranges[2 * tile], stop = ranges[2 * tile + 1];
        // Only the Gaussians up to the tile's last contributor have gradients.
        int used = 0;
        forEachTilePixel(tx, ty, width, height, [&](int px, int py) {
          used = std::max(used, last_fwd[static_cast<int64_t>(py) * width + px]);
        });
        if (used == 0) continue;
        list.gather(ids + start, std::min(used, stop - start), m2, co, op, skip.data(), val, D);
        grads.assign(static_cast<std::size_t>(list.size() * row), T(0));
        if (D == 3) {
          backwardTile<3>(list, D, tx, ty, width, height, gimg, galpha, alpha_fwd, last_fwd,
                          accum.data(), last_value.data(), grads.data());
        } else {
          backwardTile<0>(list, D, tx, ty, width, height, gimg, galpha, alpha_fwd, last_fwd,
                          accum.data(), last_value.data(), grads.data());
        }
        for (int j = 0; j < list.size(); ++j) {
          T* gb = buf + static_cast<int64_t>(list.ids[j]) * row;
          const T* gt = grads.data() + j * row;
          for (int64_t c = 0; c < row; ++c) gb[c] += gt[c];
        }
      }
    });
  });
  const at::Tensor total = buffers.sum(0);
  RasterGrads g;
  g.means2d = total.slice(1, 0, 2).contiguous();
  g.conics = total.slice(1, 2, 5).contiguous();
  g.opacities = total.select(1, 5).contiguous();
  g.values = total.slice(1, 6, row).contiguous();
  return g;
}

}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
