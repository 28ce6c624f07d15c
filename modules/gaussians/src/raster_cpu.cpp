// The CPU backend of the rasterizer: the reference for correctness. Multi-threaded over
// Gaussians (projection) and tiles (rasterization) with at::parallel_for; templated on the
// scalar type so gradient checks can run in double.
#include <ATen/Parallel.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "raster_backend.h"
#include "raster_cpu_lanes.h"
#include "raster_cpu_tiles.h"
#include "sadsplat/common/error.h"
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

namespace {

// Gaussian i's first `used` SH coefficients from the two parts (rows any stride apart) into one
// row of 3 x used values, as raster::shColor reads them.
template <typename T>
void gatherShRow(const ShParts& sh, int64_t i, int64_t used, T* row) {
  const T* dc = sh.dc.data_ptr<T>() + i * sh.dc.stride(0);
  const T* rest = sh.rest.data_ptr<T>() + i * sh.rest.stride(0);
  std::copy(dc, dc + 3, row);
  std::copy(rest, rest + 3 * (used - 1), row + 3);
}

}  // namespace

at::Tensor shForwardCpu(const ShParts& sh, const at::Tensor& means,
                        const std::array<double, 3>& campos, int degree) {
  const int64_t n = means.size(0), used = shCoefficientsForDegree(degree);
  at::Tensor colors = at::empty({n, 3}, means.options());
  AT_DISPATCH_FLOATING_TYPES(means.scalar_type(), "shForwardCpu", [&] {
    const scalar_t cam[3] = {scalar_t(campos[0]), scalar_t(campos[1]), scalar_t(campos[2])};
    const scalar_t* m = means.data_ptr<scalar_t>();
    scalar_t* c = colors.data_ptr<scalar_t>();
    at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
      scalar_t row[16 * 3];  // the coefficients the degree uses, in one row
      for (int64_t i = begin; i < end; ++i) {
        gatherShRow(sh, i, used, row);
        shColor(row, degree, m + 3 * i, cam, c + 3 * i);
      }
    });
  });
  return colors;
}

ShGrads shBackwardCpu(const ShParts& sh, const at::Tensor& means,
                      const std::array<double, 3>& campos, int degree, const at::Tensor& g_colors) {
  const int64_t n = means.size(0), used = shCoefficientsForDegree(degree);
  ShGrads g;
  g.dc = at::empty({n, 1, 3}, means.options());
  g.rest = at::zeros({n, sh.rest.size(1), 3}, means.options());
  g.means = at::zeros_like(means);
  AT_DISPATCH_FLOATING_TYPES(means.scalar_type(), "shBackwardCpu", [&] {
    const scalar_t cam[3] = {scalar_t(campos[0]), scalar_t(campos[1]), scalar_t(campos[2])};
    const int64_t rest_row = 3 * sh.rest.size(1);
    const scalar_t* m = means.data_ptr<scalar_t>();
    const scalar_t* gc = g_colors.data_ptr<scalar_t>();
    scalar_t* g_dc = g.dc.data_ptr<scalar_t>();
    scalar_t* g_rest = g.rest.data_ptr<scalar_t>();
    scalar_t* gm = g.means.data_ptr<scalar_t>();
    at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
      scalar_t row[16 * 3], g_row[16 * 3];
      for (int64_t i = begin; i < end; ++i) {
        gatherShRow(sh, i, used, row);
        std::fill(g_row, g_row + 3 * used, scalar_t(0));
        shColorBackward(row, degree, m + 3 * i, cam, gc + 3 * i, g_row, gm + 3 * i);
        std::copy(g_row, g_row + 3, g_dc + 3 * i);
        std::copy(g_row + 3, g_row + 3 * used, g_rest + i * rest_row);
      }
    });
  });
  return g;
}

namespace {

// A float's bits as an unsigned integer of the same order (negative values flipped): sorting
// these orders as the float `<` does, except that -0 sorts before +0 (binned depths lie beyond
// the near plane, so neither occurs).
inline std::uint32_t orderedBits(float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

// Sorts (depth bits << 32 | id) keys whose ids ascend: by the whole key (short lists) or by the
// depth bits alone with a stable radix sort (a pass per byte, skipped where every key has the
// same byte), which keeps the ids' order among equal depths — the same order either way.
inline void sortByDepthKeepingIdOrder(std::uint64_t* keys, int64_t count,
                                      std::vector<std::uint64_t>* scratch) {
  if (count <= 64) {
    std::sort(keys, keys + count);
    return;
  }
  scratch->resize(static_cast<std::size_t>(count));
  std::uint64_t* from = keys;
  std::uint64_t* to = scratch->data();
  for (int shift = 32; shift < 64; shift += 8) {
    int64_t offsets[256] = {};
    for (int64_t k = 0; k < count; ++k) ++offsets[(from[k] >> shift) & 0xff];
    if (offsets[(from[0] >> shift) & 0xff] == count) continue;
    int64_t sum = 0;
    for (int64_t& offset : offsets) {
      const int64_t c = offset;
      offset = sum;
      sum += c;
    }
    for (int64_t k = 0; k < count; ++k) to[offsets[(from[k] >> shift) & 0xff]++] = from[k];
    std::swap(from, to);
  }
  if (from != keys) std::copy(from, from + count, keys);
}

// Per-tile lists sorted by (depth, id): the same order the CUDA backend's stable sort gives.
// Gaussians are binned in fixed runs of kBinningRun ids, each run on one thread into its own
// (tile, id) pairs in id order; each tile's entries are then laid out run after run (so in id
// order) as (depth, id) keys and sorted: the result does not depend on the thread count.
constexpr int64_t kBinningRun = 4096;

template <typename T>
Binning binGaussians(const T* means2d, const T* conics, const int* radii, const T* opacities,
                     const T* depths, int64_t n, int width, int height) {
  const ScopedPhase phase("binning");
  const auto [tiles_x, tiles_y] = tileGrid(width, height);
  const int num_tiles = tiles_x * tiles_y;
  const int64_t runs = (n + kBinningRun - 1) / kBinningRun;
  std::vector<std::vector<std::pair<int, int>>> hits(static_cast<std::size_t>(runs));
  // counts[run * num_tiles + tile]: then, after the prefix sum, where the run's entries of the
  // tile start.
  std::vector<int64_t> counts(static_cast<std::size_t>(runs * num_tiles), 0);
  at::parallel_for(0, runs, 1, [&](int64_t run_begin, int64_t run_end) {
    for (int64_t run = run_begin; run < run_end; ++run) {
      auto& run_hits = hits[run];
      int64_t* run_counts = counts.data() + run * num_tiles;
      const int64_t last = std::min(n, (run + 1) * kBinningRun);
      for (int64_t i = run * kBinningRun; i < last; ++i) {
        if (radii[i] <= 0) continue;               // culled in projection (alphaBox would give 0)
        const T opacity = std::abs(opacities[i]);  // a closed gate's (raster_backend.h) as if open
        AlphaEllipse<T> ellipse;
        if (!alphaEllipse(means2d + 2 * i, conics + 3 * i, opacity, &ellipse)) continue;
        int rx, ry;
        alphaBox(radii[i], ellipse, &rx, &ry);
        if (rx <= 0) continue;
        int x0, y0, x1, y1;
        tileRect(means2d + 2 * i, rx, ry, tiles_x, tiles_y, &x0, &y0, &x1, &y1);
        for (int ty = y0; ty < y1; ++ty) {
          for (int tx = x0; tx < x1; ++tx) {
            if (alphaEllipseMeetsTile(ellipse, tx, ty)) {
              const int tile = ty * tiles_x + tx;
              run_hits.emplace_back(tile, static_cast<int>(i));
              ++run_counts[tile];
            }
          }
        }
      }
    }
  });
  Binning b;
  b.tile_ranges = at::empty({num_tiles, 2}, at::TensorOptions().dtype(at::kInt));
  int* ranges = b.tile_ranges.data_ptr<int>();
  int64_t total = 0;
  for (int t = 0; t < num_tiles; ++t) {
    ranges[2 * t] = static_cast<int>(total);
    for (int64_t run = 0; run < runs; ++run) {
      const int64_t count = counts[run * num_tiles + t];
      counts[run * num_tiles + t] = total;
      total += count;
    }
    ranges[2 * t + 1] = static_cast<int>(total);
  }
  std::vector<std::uint64_t> keys(static_cast<std::size_t>(total));
  at::parallel_for(0, runs, 1, [&](int64_t run_begin, int64_t run_end) {
    for (int64_t run = run_begin; run < run_end; ++run) {
      int64_t* next = counts.data() + run * num_tiles;
      for (const auto& [tile, id] : hits[run]) {
        keys[next[tile]++] =
            (static_cast<std::uint64_t>(orderedBits(static_cast<float>(depths[id]))) << 32) |
            static_cast<std::uint32_t>(id);
      }
    }
  });
  b.gaussian_ids = at::empty({total}, at::TensorOptions().dtype(at::kInt));
  int* ids = b.gaussian_ids.data_ptr<int>();
  at::parallel_for(0, num_tiles, 16, [&](int64_t begin, int64_t end) {
    std::vector<std::uint64_t> scratch;
    for (int64_t t = begin; t < end; ++t) {
      std::uint64_t* first = keys.data() + ranges[2 * t];
      const int64_t count = ranges[2 * t + 1] - ranges[2 * t];
      sortByDepthKeepingIdOrder(first, count, &scratch);
      for (int64_t k = 0; k < count; ++k) {
        ids[ranges[2 * t] + k] = static_cast<int>(first[k] & 0xffffffffu);
      }
    }
  });
  return b;
}

// Below this power a Gaussian's alpha is certainly under kMinAlpha, so pixelAlpha (and its exp)
// can be skipped; the 1e-3 margin leaves every borderline case to pixelAlpha itself, so results
// are exactly those of the CUDA backend's unconditional calls. A closed gate's (a negative
// opacity, raster_backend.h) is that of its opacity: the pixels it would reach are visited.
template <typename T>
std::vector<T> skipThresholds(const T* opacities, int64_t n) {
  std::vector<T> thresholds(static_cast<std::size_t>(n));
  at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const T opacity = std::abs(opacities[i]);
      thresholds[i] = opacity > T(0) ? std::log(T(kMinAlpha) / opacity) - T(1e-3)
                                     : std::numeric_limits<T>::infinity();
    }
  });
  return thresholds;
}

// Whether any opacity is negative (a closed gate, raster_backend.h).
template <typename T>
bool hasClosedGates(const T* opacities, int64_t n) {
  return std::any_of(opacities, opacities + n, [](T o) { return o < T(0); });
}

// The loops for a render with closed gates: the lane loops compute their own alphas without
// them, so the SSE2 rows (or the scalar loops) take such renders; the same bits either way.
CpuTileLoops loopsForClosedGates(CpuTileLoops resolved) {
  if (resolved != CpuTileLoops::kLanesAvx2 && resolved != CpuTileLoops::kLanesAvx512) {
    return resolved;
  }
  return cpuTileLoopsAvailable(CpuTileLoops::kRows) ? CpuTileLoops::kRows : CpuTileLoops::kScalar;
}

using cpu_tiles::TileList;

// The loops kFastest stands for: the AVX2 lanes where the CPU has AVX2, else the SSE2 rows, or
// those that the environment variable SADSPLAT_CPU_TILE_LOOPS names (scalar, rows, avx2, avx512:
// for timing one against another; all give the same bits). An unknown or unavailable name is an
// error. The AVX-512 lanes are not the default: on 2 cores of an AVX-512 machine they trained the
// demo (320x180, feature channels) 10 % faster than the AVX2 lanes but the 160x90 RGB benchmark
// 13 % slower (docs/measurements/cpu_speed).
CpuTileLoops fastestLoops() {
  static const CpuTileLoops chosen = [] {
    const char* env = std::getenv("SADSPLAT_CPU_TILE_LOOPS");
    if (env != nullptr && *env != '\0') {
      const std::string name = env;
      const CpuTileLoops named = name == "scalar"   ? CpuTileLoops::kScalar
                                 : name == "rows"   ? CpuTileLoops::kRows
                                 : name == "avx2"   ? CpuTileLoops::kLanesAvx2
                                 : name == "avx512" ? CpuTileLoops::kLanesAvx512
                                                    : CpuTileLoops::kFastest;
      if (named == CpuTileLoops::kFastest || !cpuTileLoopsAvailable(named)) {
        throw Error("SADSPLAT_CPU_TILE_LOOPS", "value",
                    "scalar, rows, avx2 or avx512, one that this CPU runs", name);
      }
      return named;
    }
    for (CpuTileLoops best : {CpuTileLoops::kLanesAvx2, CpuTileLoops::kRows}) {
      if (cpuTileLoopsAvailable(best)) return best;
    }
    return CpuTileLoops::kScalar;
  }();
  return chosen;
}

// `loops` resolved to the loops that run; double always takes the scalar ones.
template <typename T>
CpuTileLoops resolveLoops(CpuTileLoops loops) {
  if (!std::is_same_v<T, float>) return CpuTileLoops::kScalar;
  if (loops == CpuTileLoops::kFastest) return fastestLoops();
  if (!cpuTileLoopsAvailable(loops)) throw std::invalid_argument("CPU tile loops not available");
  return loops;
}

cpu_lanes::Isa laneIsa(CpuTileLoops loops) {
  return loops == CpuTileLoops::kLanesAvx512 ? cpu_lanes::Isa::kAvx512 : cpu_lanes::Isa::kAvx2;
}

template <typename T>
cpu_lanes::TileView tileView(const TileList<T>& list, int64_t D, int tx, int ty, int width,
                             int height) {
  if constexpr (std::is_same_v<T, float>) {
    return {list.gaussians.data(), list.values.data(), list.size(), D, tx, ty, width, height};
  } else {
    throw std::logic_error("the lane loops are for float");
  }
}

// One tile of the forward pass with `loops` (resolved). accum: kTileSize * D values.
template <typename T>
void forwardOneTile(const TileList<T>& list, int64_t D, int tx, int ty, int width, int height,
                    CpuTileLoops loops, T* accum, T* img, T* alpha_out, int* last_out) {
  if constexpr (std::is_same_v<T, float>) {
    if (loops == CpuTileLoops::kLanesAvx2 || loops == CpuTileLoops::kLanesAvx512) {
      cpu_lanes::forwardTileLanes(laneIsa(loops), tileView(list, D, tx, ty, width, height), accum,
                                  img, alpha_out, last_out);
      return;
    }
#if SADSPLAT_CPU_RASTER_SIMD
    if (loops == CpuTileLoops::kRows) {
      if (D == 3) {
        cpu_tiles::forwardTileRows<3>(list, D, tx, ty, width, height, accum, img, alpha_out,
                                      last_out);
      } else {
        cpu_tiles::forwardTileRows<0>(list, D, tx, ty, width, height, accum, img, alpha_out,
                                      last_out);
      }
      return;
    }
#endif
  }
  if (D == 3) {
    cpu_tiles::forwardTile<3>(list, D, tx, ty, width, height, accum, img, alpha_out, last_out);
  } else {
    cpu_tiles::forwardTile<0>(list, D, tx, ty, width, height, accum, img, alpha_out, last_out);
  }
}

// One tile of the backward pass (see forwardOneTile). scratch: backwardScratchFloats(D) values.
template <typename T>
void backwardOneTile(const TileList<T>& list, int64_t D, int tx, int ty, int width, int height,
                     CpuTileLoops loops, const T* gimg, const T* galpha, const T* alpha_fwd,
                     const int* last_fwd, T* scratch, T* grads) {
  if constexpr (std::is_same_v<T, float>) {
    if (loops == CpuTileLoops::kLanesAvx2 || loops == CpuTileLoops::kLanesAvx512) {
      cpu_lanes::backwardTileLanes(laneIsa(loops), tileView(list, D, tx, ty, width, height), gimg,
                                   galpha, alpha_fwd, last_fwd, scratch, grads);
      return;
    }
#if SADSPLAT_CPU_RASTER_SIMD
    if (loops == CpuTileLoops::kRows) {
      if (D == 3) {
        cpu_tiles::backwardTileRows<3>(list, D, tx, ty, width, height, gimg, galpha, alpha_fwd,
                                       last_fwd, scratch, grads);
      } else {
        cpu_tiles::backwardTileRows<0>(list, D, tx, ty, width, height, gimg, galpha, alpha_fwd,
                                       last_fwd, scratch, grads);
      }
      return;
    }
#endif
  }
  if (D == 3) {
    cpu_tiles::backwardTile<3>(list, D, tx, ty, width, height, gimg, galpha, alpha_fwd, last_fwd,
                               grads);
  } else {
    cpu_tiles::backwardTile<0>(list, D, tx, ty, width, height, gimg, galpha, alpha_fwd, last_fwd,
                               grads);
  }
}

}  // namespace

bool cpuTileLoopsAvailable(CpuTileLoops loops) {
  switch (loops) {
    case CpuTileLoops::kFastest:
    case CpuTileLoops::kScalar:
      return true;
    case CpuTileLoops::kRows:
      return SADSPLAT_CPU_RASTER_SIMD != 0;
    case CpuTileLoops::kLanesAvx2:
      return cpu_lanes::lanesAvailable(cpu_lanes::Isa::kAvx2);
    case CpuTileLoops::kLanesAvx512:
      return cpu_lanes::lanesAvailable(cpu_lanes::Isa::kAvx512);
  }
  return false;
}

RasterResult rasterizeForwardCpu(const at::Tensor& means2d, const at::Tensor& conics,
                                 const at::Tensor& opacities, const at::Tensor& values,
                                 const at::Tensor& radii, const at::Tensor& depths, int width,
                                 int height, CpuTileLoops loops) {
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
    const CpuTileLoops resolved = resolveLoops<T>(loops);
    const CpuTileLoops tile_loops =
        hasClosedGates(op, n) ? loopsForClosedGates(resolved) : resolved;
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
    // Tiles are handed out one at a time (their lists differ in length many times over; a
    // static split leaves one thread idle); every pixel is written once, so the result does not
    // depend on which thread draws which tile.
    std::atomic<int64_t> next_tile{0};
    at::parallel_for(0, at::get_num_threads(), 1, [&](int64_t, int64_t) {
      std::vector<T> accum(static_cast<std::size_t>(kTileSize * D));
      TileList<T> list;
      for (int64_t tile = next_tile++; tile < num_tiles; tile = next_tile++) {
        const int tx = static_cast<int>(tile % tiles_x), ty = static_cast<int>(tile / tiles_x);
        const int start = ranges[2 * tile], stop = ranges[2 * tile + 1];
        list.gather(ids + start, stop - start, m2, co, op, skip.data(), val, D);
        forwardOneTile(list, D, tx, ty, width, height, tile_loops, accum.data(), img, alpha_out,
                       last_out);
      }
    });
  });
  return out;
}

RasterGrads rasterizeBackwardCpu(const at::Tensor& means2d, const at::Tensor& conics,
                                 const at::Tensor& opacities, const at::Tensor& values,
                                 const RasterResult& fwd, const at::Tensor& g_image,
                                 const at::Tensor& g_alpha, CpuTileLoops loops) {
  const int64_t n = means2d.size(0);
  const int64_t D = values.size(1);
  const int height = static_cast<int>(fwd.alpha.size(0));
  const int width = static_cast<int>(fwd.alpha.size(1));
  // One gradient buffer per thread (tiles share Gaussians), summed at the end; each tile sums
  // into its own list-ordered rows first and adds them to its buffer once. Row layout:
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
    const CpuTileLoops resolved = resolveLoops<T>(loops);
    const CpuTileLoops tile_loops =
        hasClosedGates(op, n) ? loopsForClosedGates(resolved) : resolved;
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
    // Per tile: how far its pixels walk its list (the sum of their `last`: the backward's work,
    // which differs many times over between tiles) and the furthest (entries behind every
    // pixel's last contributor get no gradient).
    std::vector<int64_t> work_before(static_cast<std::size_t>(num_tiles) + 1, 0);
    std::vector<int> used(static_cast<std::size_t>(num_tiles), 0);
    for (int tile = 0; tile < num_tiles; ++tile) {
      int64_t walked = 0;
      cpu_tiles::forEachTilePixel(
          tile % tiles_x, tile / tiles_x, width, height, [&](int px, int py) {
            const int last = last_fwd[static_cast<int64_t>(py) * width + px];
            walked += last;
            used[tile] = std::max(used[tile], last);
          });
      work_before[tile + 1] = work_before[tile] + walked;
    }
    // Buffer k sums a contiguous run of tiles of about 1/threads of the work, in tile order, and
    // the buffers are summed in order: the gradients depend on the thread count (as with any
    // split) but not on which thread runs which run.
    std::vector<int> run_start(static_cast<std::size_t>(threads) + 1, num_tiles);
    for (int k = 0; k < threads; ++k) {
      const int64_t target = work_before.back() * k / threads;
      run_start[k] = static_cast<int>(
          std::lower_bound(work_before.begin() + 1, work_before.end(), target + 1) -
          (work_before.begin() + 1));
    }
    run_start[0] = 0;
    at::parallel_for(0, threads, 1, [&](int64_t first_run, int64_t end_run) {
      std::vector<T> scratch(static_cast<std::size_t>(cpu_lanes::backwardScratchFloats(D)));
      std::vector<T> grads;
      TileList<T> list;
      list.closed_gates = fwd.closed_gates;
      for (int64_t k = first_run; k < end_run; ++k) {
        T* buf = buf_base + k * n * row;
        for (int tile = run_start[k]; tile < run_start[k + 1]; ++tile) {
          if (used[tile] == 0) continue;
          const int tx = tile % tiles_x, ty = tile / tiles_x;
          const int start = ranges[2 * tile], stop = ranges[2 * tile + 1];
          list.gather(ids + start, std::min(used[tile], stop - start), m2, co, op, skip.data(), val,
                      D);
          grads.assign(static_cast<std::size_t>(list.size() * row), T(0));
          backwardOneTile(list, D, tx, ty, width, height, tile_loops, gimg, galpha, alpha_fwd,
                          last_fwd, scratch.data(), grads.data());
          for (int j = 0; j < list.size(); ++j) {
            T* gb = buf + static_cast<int64_t>(list.ids[j]) * row;
            const T* gt = grads.data() + j * row;
            for (int64_t c = 0; c < row; ++c) gb[c] += gt[c];
          }
        }
      }
    });
  });
  // The buffers summed in order, straight into the four gradients.
  RasterGrads g;
  g.means2d = at::empty({n, 2}, values.options());
  g.conics = at::empty({n, 3}, values.options());
  g.opacities = at::empty({n}, values.options());
  g.values = at::empty({n, D}, values.options());
  AT_DISPATCH_FLOATING_TYPES(values.scalar_type(), "rasterizeBackwardCpu sums", [&] {
    using T = scalar_t;
    const T* buf = buffers.data_ptr<T>();
    T* out[4] = {g.means2d.data_ptr<T>(), g.conics.data_ptr<T>(), g.opacities.data_ptr<T>(),
                 g.values.data_ptr<T>()};
    const int64_t first[4] = {0, 2, 5, 6}, width[4] = {2, 3, 1, D};
    at::parallel_for(0, n, kGaussianGrain, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        for (int part = 0; part < 4; ++part) {
          for (int64_t c = 0; c < width[part]; ++c) {
            const int64_t at_row = i * row + first[part] + c;
            T sum = buf[at_row];
            for (int k = 1; k < threads; ++k) sum += buf[k * n * row + at_row];
            out[part][i * width[part] + c] = sum;
          }
        }
      }
    });
  });
  return g;
}

}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
