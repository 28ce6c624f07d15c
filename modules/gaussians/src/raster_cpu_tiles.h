#pragma once
// The CPU rasterizer's per-tile loops (raster_cpu.cpp runs them over the tiles): the scalar
// reference, for any scalar type, and for float a vectorised form that tests a Gaussian's skip
// threshold at one tile row's 16 pixels at once with SSE2 (x86-64's baseline). Most
// (pixel, Gaussian) pairs of a tile's list are skipped (~92 % on the demo city at 160x90); the
// vectorised form leaves out the rows outside a Gaussian's row range (rowRange) without a test,
// and does the pairs that are not skipped with the scalar code, pixel by pixel in the same
// order, so its images and gradients are bit-identical to the scalar form's
// (test_raster_cpu_paths.cpp).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#define SADSPLAT_CPU_RASTER_SIMD 1
#else
#define SADSPLAT_CPU_RASTER_SIMD 0
#endif

#include "sadsplat/gaussians/raster_math.h"

namespace sadsplat {
namespace gaussians {
namespace raster {
namespace cpu_tiles {

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
  // The pixel-centre rows y with y_lo <= y <= y_hi are the only ones where some pixel may pass the
  // skip test (rowRange); NaN bounds (no bound) exclude no row.
  T y_lo, y_hi;
};

// Rows that Gaussian (mean_y, conic, skip) may reach: at a given dy the largest power over all x
// is -0.5 dy^2 / S_yy, with S_yy = a / (a c - b^2) the covariance's y variance (conic (a, b, c)),
// so no pixel with |dy| > sqrt(-2 skip S_yy) passes `power >= skip`. Widened by 0.1 % + 0.05 px
// for the float rounding of the skip test (its power's error is ~1e-4 at most, dy's a thousandth of
// a pixel); in double. A degenerate conic, an opacity <= 0 (skip = +inf) or a NaN give an
// unbounded or NaN range, which excludes no row: the skip test decides, as without the range.
template <typename T>
inline void rowRange(T mean_y, const T conic[3], T skip, T* y_lo, T* y_hi) {
  const double a = conic[0], b = conic[1], c = conic[2];
  const double half = std::sqrt(-2.0 * double(skip) * a / (a * c - b * b));
  const double h = half * (1 + 1e-3) + 0.05;
  *y_lo = T(double(mean_y) - h);
  *y_hi = T(double(mean_y) + h);
}

// A tile's Gaussians copied front to back into contiguous arrays (values as [L, D]): every pixel
// of the tile walks the same list, so gathering it once per tile turns 256 indirect, scattered
// reads per Gaussian into one. The arithmetic per pixel is unchanged.
template <typename T>
struct TileList {
  std::vector<PackedGaussian<T>> gaussians;
  std::vector<T> values;
  const int* ids = nullptr;  // into the binning's gaussian_ids
  // The backward gives closed gates (negative opacities, raster_backend.h) their gradient.
  bool closed_gates = false;

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
      if constexpr (std::is_same_v<T, float>) {
        rowRange(p.mean2d[1], p.conic, p.skip, &p.y_lo, &p.y_hi);
      } else {  // only the float loops read the range
        p.y_lo = p.y_hi = std::numeric_limits<T>::quiet_NaN();
      }
      std::copy(all_values + g * D, all_values + (g + 1) * D, values.begin() + j * D);
    }
  }
};

// Blends Gaussian j (past the skip test) into the pixel at (fx, fy): its channel sums `accum`,
// transmittance `trans` and last contributor `last`. False when the pixel saturates before it
// (the pixel stops there). The forward's per-pixel arithmetic lives only here: the scalar and the
// vectorised loops both call it, so they round alike.
template <typename T>
inline bool blendGaussian(const PackedGaussian<T>& p, const T* v, int64_t D, int j, T fx, T fy,
                          T* accum, T* trans, int* last) {
  T G = T(0);
  bool clamped;
  const T alpha = pixelAlpha(p.mean2d, p.conic, p.opacity, fx, fy, &G, &clamped);
  if (alpha == T(0)) {
    // A closed gate it would blend at counts in `last`: the backward visits it there.
    if (closedGateReaches(p.opacity, G)) *last = j + 1;
    return true;
  }
  const T next = *trans * (T(1) - alpha);
  if (next < T(kMinTransmittance)) return false;
  const T w = alpha * *trans;
  for (int64_t ch = 0; ch < D; ++ch) accum[ch] += w * v[ch];
  *trans = next;
  *last = j + 1;
  return true;
}

// The backward of blendGaussian for the pixel at (fx, fy), walked back to front: adds Gaussian
// j's gradients (mean2d, conic, opacity, values) to its row `gb`. The opacity gradient needs the
// dot product of the pixel gradient with the colour accumulated behind the Gaussian; the pixel
// gradient is the same for every Gaussian of the pixel, so that product follows the colour's own
// recurrence (behind <- a * value + (1 - a) * behind) and is carried as one number, `behind`,
// with `last_dot` (value . gradient of the Gaussian visited before) — D multiply-adds per pair
// fewer than carrying the D-channel colour (the CUDA backward does the same). The pixel's state:
// `trans`, `last_alpha`, `behind`, `last_dot` (updated); gpix its image gradient, g_alpha_out its
// alpha gradient, final_trans its transmittance after the forward. Shared by both loops, as above.
// A closed gate (raster_backend.h) at a pixel it would reach: a contributor of alpha 0 — the
// transmittance stays, no value or geometry gradient; its opacity gradient is G times the alpha
// gradient at alpha 0.
template <typename T>
inline void unblendClosedGate(T G, const T* v, int64_t D, const T* gpix, T g_alpha_out,
                              T final_trans, T trans, T* last_alpha, T* behind, T* last_dot,
                              T* gb) {
  T dot = T(0);
  for (int64_t ch = 0; ch < D; ++ch) dot += v[ch] * gpix[ch];
  *behind = *last_alpha * *last_dot + (T(1) - *last_alpha) * *behind;
  const T g_a = (dot - *behind) * trans + g_alpha_out * final_trans;
  *last_dot = dot;
  *last_alpha = T(0);
  gb[5] += G * g_a;
}

template <typename T>
inline void unblendGaussian(const PackedGaussian<T>& p, const T* v, int64_t D, T fx, T fy,
                            const T* gpix, T g_alpha_out, T final_trans, T* trans, T* last_alpha,
                            T* behind, T* last_dot, T* gb, bool closed_gates) {
  T G = T(0);
  bool clamped;
  const T alpha = pixelAlpha(p.mean2d, p.conic, p.opacity, fx, fy, &G, &clamped);
  if (alpha == T(0)) {
    if (closed_gates && closedGateReaches(p.opacity, G)) {
      unblendClosedGate(G, v, D, gpix, g_alpha_out, final_trans, *trans, last_alpha, behind,
                        last_dot, gb);
    }
    return;
  }
  *trans = *trans / (T(1) - alpha);
  const T w = alpha * *trans;
  T dot = T(0);
  for (int64_t ch = 0; ch < D; ++ch) {
    dot += v[ch] * gpix[ch];
    gb[6 + ch] += w * gpix[ch];
  }
  *behind = *last_alpha * *last_dot + (T(1) - *last_alpha) * *behind;
  T g_a = (dot - *behind) * *trans;
  g_a += g_alpha_out * final_trans / (T(1) - alpha);
  *last_dot = dot;
  *last_alpha = alpha;
  pixelAlphaBackward(p.mean2d, p.conic, p.opacity, fx, fy, G, clamped, g_a, gb, gb + 2, gb + 5);
}

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
      if (!blendGaussian(p, val + j * D, D, j, fx, fy, accum, &trans, &last)) break;
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
                  const T* gimg, const T* galpha, const T* alpha_fwd, const int* last_fwd,
                  T* grads) {
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
    T last_alpha = T(0), behind = T(0), last_dot = T(0);
    for (int j = last_fwd[pix] - 1; j >= 0; --j) {
      const PackedGaussian<T>& p = pg[j];
      if (gaussianPower(p.conic, p.mean2d[0] - fx, p.mean2d[1] - fy) < p.skip) continue;
      unblendGaussian(p, val + j * D, D, fx, fy, gpix, galpha[pix], final_trans, &trans,
                      &last_alpha, &behind, &last_dot, grads + j * row, list.closed_gates);
    }
  });
}

#if SADSPLAT_CPU_RASTER_SIMD

// One tile row's pixel centres along x, as four 4-lane vectors (lane l: pixel x0 + l).
struct RowLanes {
  __m128 fx[4];
  unsigned valid;  // bit l: pixel x0 + l lies inside the image

  RowLanes(int x0, int width) {
    for (int q = 0; q < 4; ++q) {
      const int x = x0 + 4 * q;
      fx[q] = _mm_setr_ps(float(x) + 0.5f, float(x + 1) + 0.5f, float(x + 2) + 0.5f,
                          float(x + 3) + 0.5f);
    }
    const int lanes = std::min(width - x0, kTileSize);
    valid = lanes >= 32 ? ~0u : (1u << lanes) - 1u;
  }
};

// Bit l set where pixel lane l does not skip Gaussian p: the negation of the scalar test
// `gaussianPower(...) < p.skip` (a NaN power is not skipped there either), computed with the same
// float operations in the same order (no FMA on x86-64's baseline), so the bits agree exactly.
inline unsigned notSkipped(const PackedGaussian<float>& p, const RowLanes& row, float fy) {
  const float dy = p.mean2d[1] - fy;
  const __m128 c0 = _mm_set1_ps(p.conic[0]), c1 = _mm_set1_ps(p.conic[1]);
  const __m128 dy_term = _mm_set1_ps(p.conic[2] * dy * dy), vdy = _mm_set1_ps(dy);
  const __m128 mx = _mm_set1_ps(p.mean2d[0]), half = _mm_set1_ps(-0.5f);
  const __m128 skip = _mm_set1_ps(p.skip);
  unsigned bits = 0;
  for (int q = 0; q < 4; ++q) {
    const __m128 dx = _mm_sub_ps(mx, row.fx[q]);
    const __m128 sum = _mm_add_ps(_mm_mul_ps(_mm_mul_ps(c0, dx), dx), dy_term);
    const __m128 power = _mm_sub_ps(_mm_mul_ps(half, sum), _mm_mul_ps(_mm_mul_ps(c1, dx), vdy));
    bits |= static_cast<unsigned>(_mm_movemask_ps(_mm_cmpnlt_ps(power, skip))) << (4 * q);
  }
  return bits;
}

// forwardTile for float, a tile row at a time: per Gaussian one vectorised skip test for the
// row's 16 pixels, then blendGaussian for the pixels that do not skip it.
// `accum`: kTileSize * D floats.
template <int kD>
void forwardTileRows(const TileList<float>& list, int64_t dynamic_d, int tx, int ty, int width,
                     int height, float* accum, float* img, float* alpha_out, int* last_out) {
  const int64_t D = kD > 0 ? kD : dynamic_d;
  const PackedGaussian<float>* pg = list.gaussians.data();
  const float* val = list.values.data();
  const int count = list.size();
  const int x0 = tx * kTileSize;
  const RowLanes row(x0, width);
  const int lanes = std::min(width - x0, kTileSize);
  const int y_end = std::min(height, (ty + 1) * kTileSize);
  float trans[kTileSize];
  int last[kTileSize];
  for (int py = ty * kTileSize; py < y_end; ++py) {
    const float fy = float(py) + 0.5f;
    std::fill(accum, accum + kTileSize * D, 0.f);
    std::fill(trans, trans + kTileSize, 1.f);
    std::fill(last, last + kTileSize, 0);
    unsigned active = row.valid;
    for (int j = 0; j < count && active != 0; ++j) {
      const PackedGaussian<float>& p = pg[j];
      if (fy < p.y_lo || fy > p.y_hi) continue;  // every pixel of the row skips it
      for (unsigned bits = notSkipped(p, row, fy) & active; bits != 0; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        if (!blendGaussian(p, val + j * D, D, j, float(x0 + l) + 0.5f, fy, accum + l * D, &trans[l],
                           &last[l])) {
          active &= ~(1u << l);
        }
      }
    }
    for (int l = 0; l < lanes; ++l) {
      const int64_t pix = static_cast<int64_t>(py) * width + x0 + l;
      std::copy(accum + l * D, accum + (l + 1) * D, img + pix * D);
      alpha_out[pix] = 1.f - trans[l];
      last_out[pix] = last[l];
    }
  }
}

// backwardTile for float, a tile row at a time (see forwardTileRows). For each Gaussian the
// row's pixels add their gradients in pixel order, rows in order: the same sequence of additions
// to every gradient as backwardTile's pixel-by-pixel walk. `row_buffer`: 6 + D.
template <int kD>
void backwardTileRows(const TileList<float>& list, int64_t dynamic_d, int tx, int ty, int width,
                      int height, const float* gimg, const float* galpha, const float* alpha_fwd,
                      const int* last_fwd, float* row_buffer, float* grads) {
  const int64_t D = kD > 0 ? kD : dynamic_d;
  const int64_t grad_row = 6 + D;
  const PackedGaussian<float>* pg = list.gaussians.data();
  const float* val = list.values.data();
  const int x0 = tx * kTileSize;
  const RowLanes row(x0, width);
  const int lanes = std::min(width - x0, kTileSize);
  const int y_end = std::min(height, (ty + 1) * kTileSize);
  float trans[kTileSize], final_trans[kTileSize], last_alpha[kTileSize], g_out[kTileSize];
  float behind[kTileSize], last_dot[kTileSize];
  int last[kTileSize];
  // One Gaussian's gradient row: a fixed array for RGB, the caller's buffer otherwise.
  float rgb_row[6 + 3];
  float* gb = kD == 3 ? rgb_row : row_buffer;
  for (int py = ty * kTileSize; py < y_end; ++py) {
    const float fy = float(py) + 0.5f;
    const int64_t pix0 = static_cast<int64_t>(py) * width + x0;
    int end = 0;
    for (int l = 0; l < kTileSize; ++l) {
      const bool inside = l < lanes;
      final_trans[l] = inside ? 1.f - alpha_fwd[pix0 + l] : 1.f;
      trans[l] = final_trans[l];
      last[l] = inside ? last_fwd[pix0 + l] : 0;
      g_out[l] = inside ? galpha[pix0 + l] : 0.f;
      last_alpha[l] = 0.f;
      behind[l] = 0.f;
      last_dot[l] = 0.f;
      end = std::max(end, last[l]);
    }
    for (int j = end - 1; j >= 0; --j) {
      const PackedGaussian<float>& p = pg[j];
      if (fy < p.y_lo || fy > p.y_hi) continue;  // every pixel of the row skips it
      // The pixels whose last contributor lies at or behind list position j.
      unsigned live = 0;
      for (int l = 0; l < lanes; ++l) live |= static_cast<unsigned>(last[l] > j) << l;
      unsigned bits = notSkipped(p, row, fy) & live;
      if (bits == 0) continue;
      // The row's additions to Gaussian j's gradients, in lane order, on a local copy of its
      // gradient row (kept in registers for RGB), written back once.
      float* gj = grads + j * grad_row;
      std::copy(gj, gj + grad_row, gb);
      for (; bits != 0; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        unblendGaussian(p, val + j * D, D, float(x0 + l) + 0.5f, fy, gimg + (pix0 + l) * D,
                        g_out[l], final_trans[l], &trans[l], &last_alpha[l], &behind[l],
                        &last_dot[l], gb, list.closed_gates);
      }
      std::copy(gb, gb + grad_row, gj);
    }
  }
}

#endif  // SADSPLAT_CPU_RASTER_SIMD

}  // namespace cpu_tiles
}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
