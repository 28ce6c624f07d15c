// The lane loops of raster_cpu_lanes.h, included once per instruction set by
// raster_cpu_lanes_avx2.cpp / raster_cpu_lanes_avx512.cpp with SADSPLAT_LANES_NS naming the
// set's namespace. Everything but the two entry points has internal linkage, and nothing here
// calls an inline function or template of another header (std::min, the raster_math.h templates):
// a copy of those compiled for this set could be the one the linker keeps for the whole program.
// Each lane repeats, operation for operation, the scalar code it stands for; the comments name it.
#include <immintrin.h>

#include <cstdint>
#include <cstring>

#include "raster_cpu_lanes.h"

#ifndef SADSPLAT_LANES_NS
#error "define SADSPLAT_LANES_NS before including raster_cpu_lanes_impl.h"
#endif

namespace sadsplat {
namespace gaussians {
namespace raster {
namespace cpu_lanes {
namespace SADSPLAT_LANES_NS {
namespace {

constexpr int kRow = kTileSize;  // pixels of a tile row
static_assert(kRow == 16, "a tile row has 16 pixels");
// Lanes per vector: 8 with AVX2 (a row is two chunks), 16 with AVX-512 (one).
#if defined(__AVX512F__)
constexpr int kW = 16;
#else
constexpr int kW = 8;
#endif
constexpr int kChunks = kRow / kW;
constexpr unsigned kChunkMask = (1u << kW) - 1u;
// A chunk with fewer candidate pixels than this takes the per-pixel path: below it the vector
// path's fixed cost (an exp on every lane) is more than the pixels' own.
constexpr int kMinVectorPixels = 3;

typedef float Vf __attribute__((vector_size(4 * kW)));
typedef int32_t Vi __attribute__((vector_size(4 * kW)));

using cpu_tiles::PackedGaussian;

// Bit l set where lane l of a comparison result is true (-1).
inline unsigned laneBits(Vi m) {
#if defined(__AVX512F__)
  __m512i v;
  std::memcpy(&v, &m, sizeof v);
  return static_cast<unsigned>(_mm512_test_epi32_mask(v, v));
#else
  __m256 v;
  std::memcpy(&v, &m, sizeof v);
  return static_cast<unsigned>(_mm256_movemask_ps(v));
#endif
}

inline Vf splat(float s) { return Vf{} + s; }
inline Vf loadVf(const float* p) {
  Vf v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void storeVf(float* p, Vf v) { std::memcpy(p, &v, sizeof v); }

inline int lowestLane(unsigned bits) { return __builtin_ctz(bits); }
inline int smaller(int a, int b) { return a < b ? a : b; }

// expPoly (raster_math.h) on every lane, repeated here (an inline function of that header must
// not be compiled in this unit, see above). The per-pixel path takes its exp from here too: one
// vector of them costs about what one scalar exp does.
inline Vf expLanes(Vf x) {
  x = x < -87.f ? splat(-87.f) : x;
  x = x > 88.f ? splat(88.f) : x;
  const Vf k = (x * 1.44269504088896341f + 12582912.f) - 12582912.f;
  const Vf r = (x - k * 0.693359375f) - k * -2.12194440e-4f;
  const Vf z = r * r;
  Vf p = splat(1.9875691500e-4f);
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  const Vf y = (p * z + r) + 1.f;
  const Vi ki = k == k ? __builtin_convertvector(k, Vi) : Vi{};
  const Vi bits = (ki + 127) * (1 << 23);
  Vf scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return y * scale;
}

// A Gaussian's power at pixel centres fx (gaussianPower with dx = mean_x - fx, dy = mean_y - fy).
inline Vf lanePower(const PackedGaussian<float>& p, Vf fx, float dy) {
  const Vf dx = p.mean2d[0] - fx;
  return -0.5f * (p.conic[0] * dx * dx + p.conic[2] * dy * dy) - p.conic[1] * dx * dy;
}

// pixelAlpha from the power and G = exp(power): 0 where power > 0 or alpha < kMinAlpha; clamped
// where alpha hit kMaxAlpha. One pixel, and every lane.
inline float alphaOne(const PackedGaussian<float>& p, float power, float G, bool* clamped) {
  if (power > 0.f) return 0.f;
  const float raw = p.opacity * G;
  *clamped = raw > float(kMaxAlpha);
  const float alpha = *clamped ? float(kMaxAlpha) : raw;
  return alpha < float(kMinAlpha) ? 0.f : alpha;
}

struct LaneAlpha {
  Vf G, alpha;
  Vi clamped;
};

inline LaneAlpha alphaLanes(const PackedGaussian<float>& p, Vf power) {
  LaneAlpha a;
  a.G = expLanes(power);
  const Vf raw = p.opacity * a.G;
  a.clamped = raw > float(kMaxAlpha);
  Vf alpha = a.clamped ? splat(float(kMaxAlpha)) : raw;
  alpha = alpha < float(kMinAlpha) ? splat(0.f) : alpha;
  a.alpha = power > 0.f ? splat(0.f) : alpha;
  return a;
}

// dst[0, n) += w * src[0, n), element by element (vectors where they fit).
inline void addScaled(float* dst, const float* src, float w, int64_t n) {
  int64_t c = 0;
  for (; c + kW <= n; c += kW) storeVf(dst + c, loadVf(dst + c) + w * loadVf(src + c));
  for (; c < n; ++c) dst[c] += w * src[c];
}

template <int kD>
inline void addValues(float* acc, const float* v, float w, int64_t D) {
  if (kD == 3) {
    for (int ch = 0; ch < 3; ++ch) acc[ch] += w * v[ch];
  } else {
    addScaled(acc, v, w, D);
  }
}

// The pixel centres of a tile row from x0 (x0 + l + 0.5 as the scalar loops compute it), by chunk.
struct RowCentres {
  alignas(64) float fx[kRow];
  RowCentres(int x0) {
    for (int l = 0; l < kRow; ++l) fx[l] = float(x0 + l) + 0.5f;
  }
  Vf chunk(int c) const { return loadVf(fx + c * kW); }
};

// forwardTileRows (raster_cpu_tiles.h) with each chunk's pixels in lanes; the per-pixel state
// lives in arrays that both paths read and write.
template <int kD>
void forwardRows(const TileView& t, float* accum, float* img, float* alpha_out, int* last_out) {
  const int64_t D = kD > 0 ? kD : t.D;
  const PackedGaussian<float>* pg = t.gaussians;
  const int x0 = t.tx * kTileSize;
  const int lanes = smaller(t.width - x0, kTileSize);
  const int y_end = smaller(t.height, (t.ty + 1) * kTileSize);
  const RowCentres centres(x0);
  const unsigned valid = lanes >= 32 ? ~0u : (1u << lanes) - 1u;
  alignas(64) float trans[kRow], power_of[kW], G_of[kW], w_of[kW];
  alignas(64) int32_t last[kRow];
  for (int py = t.ty * kTileSize; py < y_end; ++py) {
    const float fy = float(py) + 0.5f;
    for (int64_t i = 0; i < kTileSize * D; ++i) accum[i] = 0.f;
    for (int l = 0; l < kRow; ++l) {
      trans[l] = 1.f;
      last[l] = 0;
    }
    unsigned active = valid;
    for (int j = 0; j < t.count && active != 0; ++j) {
      const PackedGaussian<float>& p = pg[j];
      if (fy < p.y_lo || fy > p.y_hi) continue;  // every pixel of the row skips it
      const float dy = p.mean2d[1] - fy;
      const float* v = t.values + j * D;
      for (int c = 0; c < kChunks; ++c) {
        const unsigned chunk_active = (active >> (c * kW)) & kChunkMask;
        if (chunk_active == 0) continue;
        const Vf power = lanePower(p, centres.chunk(c), dy);
        // The scalar loops' skip test (a NaN power is not skipped).
        unsigned bits = laneBits(~(power < p.skip)) & chunk_active;
        if (bits == 0) continue;
        const int base = c * kW;
        if (__builtin_popcount(bits) < kMinVectorPixels) {
          storeVf(power_of, power);
          storeVf(G_of, expLanes(power));
          for (; bits != 0; bits &= bits - 1) {  // blendGaussian, pixel by pixel
            const int k = lowestLane(bits), l = base + k;
            bool clamped;
            const float alpha = alphaOne(p, power_of[k], G_of[k], &clamped);
            if (alpha == 0.f) continue;
            const float next = trans[l] * (1.f - alpha);
            if (next < float(kMinTransmittance)) {
              active &= ~(1u << l);
              continue;
            }
            addValues<kD>(accum + l * D, v, alpha * trans[l], D);
            trans[l] = next;
            last[l] = j + 1;
          }
          continue;
        }
        // blendGaussian on every lane of the chunk.
        Vi candidate;
        for (int k = 0; k < kW; ++k) candidate[k] = (bits >> k) & 1u ? -1 : 0;
        const LaneAlpha a = alphaLanes(p, power);
        const Vf tr = loadVf(trans + base);
        const Vi contributes = candidate & (a.alpha != 0.f);
        const Vf next = tr * (1.f - a.alpha);
        const Vi saturates = contributes & (next < float(kMinTransmittance));
        active &= ~(laneBits(saturates) << base);
        const Vi blends = contributes & ~saturates;
        unsigned blend_bits = laneBits(blends);
        if (blend_bits == 0) continue;
        storeVf(w_of, a.alpha * tr);
        storeVf(trans + base, blends ? next : tr);
        Vi lst;
        std::memcpy(&lst, last + base, sizeof lst);
        lst = blends ? (Vi{} + (j + 1)) : lst;
        std::memcpy(last + base, &lst, sizeof lst);
        for (; blend_bits != 0; blend_bits &= blend_bits - 1) {
          const int k = lowestLane(blend_bits);
          addValues<kD>(accum + (base + k) * D, v, w_of[k], D);
        }
      }
    }
    for (int l = 0; l < lanes; ++l) {
      const int64_t pix = static_cast<int64_t>(py) * t.width + x0 + l;
      std::memcpy(img + pix * D, accum + l * D, sizeof(float) * D);
      alpha_out[pix] = 1.f - trans[l];
      last_out[pix] = last[l];
    }
  }
}

// The per-pixel state of the backward's recurrence (unblendGaussian), one array per quantity.
struct BackState {
  alignas(64) float trans[kRow], final_trans[kRow], g_out[kRow];
  alignas(64) float last_alpha[kRow], behind[kRow], last_dot[kRow];
  alignas(64) int32_t last[kRow];
};

// backwardTileRows (raster_cpu_tiles.h) with each chunk's pixels in lanes.
template <int kD>
void backwardRows(const TileView& t, const float* gimg, const float* galpha, const float* alpha_fwd,
                  const int* last_fwd, float* scratch, float* grads) {
  const int64_t D = kD > 0 ? kD : t.D;
  const int64_t grad_row = 6 + D;
  const PackedGaussian<float>* pg = t.gaussians;
  const int x0 = t.tx * kTileSize;
  const int lanes = smaller(t.width - x0, kTileSize);
  const int y_end = smaller(t.height, (t.ty + 1) * kTileSize);
  const RowCentres centres(x0);
  // The row's pixel gradients by channel ([D][16]: channel ch of the row's pixels together) and
  // one Gaussian's gradient row.
  float* g_by_channel = scratch;
  float* gb = scratch + kRow * D;
  BackState st;
  alignas(64) float power_of[kW], G_of[kW], w_of[kW], g_opacity_of[kW], g_mean_x_of[kW],
      g_mean_y_of[kW];
  alignas(64) float g_conic0_of[kW], g_conic1_of[kW], g_conic2_of[kW];
  alignas(64) int32_t clamped_of[kW];
  for (int py = t.ty * kTileSize; py < y_end; ++py) {
    const float fy = float(py) + 0.5f;
    const int64_t pix0 = static_cast<int64_t>(py) * t.width + x0;
    int end = 0;
    for (int l = 0; l < kRow; ++l) {
      const bool inside = l < lanes;
      st.final_trans[l] = inside ? 1.f - alpha_fwd[pix0 + l] : 1.f;
      st.trans[l] = st.final_trans[l];
      st.last[l] = inside ? last_fwd[pix0 + l] : 0;
      st.g_out[l] = inside ? galpha[pix0 + l] : 0.f;
      st.last_alpha[l] = 0.f;
      st.behind[l] = 0.f;
      st.last_dot[l] = 0.f;
      end = st.last[l] > end ? st.last[l] : end;
    }
    bool by_channel = false;  // g_by_channel holds this row (filled for its first dense chunk)
    for (int j = end - 1; j >= 0; --j) {
      const PackedGaussian<float>& p = pg[j];
      if (fy < p.y_lo || fy > p.y_hi) continue;  // every pixel of the row skips it
      const float dy = p.mean2d[1] - fy;
      const float* v = t.values + j * D;
      float* gj = grads + j * grad_row;
      bool row_loaded = false;  // gb holds Gaussian j's row (copied on the first addition)
      for (int c = 0; c < kChunks; ++c) {
        const int base = c * kW;
        Vi lst;
        std::memcpy(&lst, st.last + base, sizeof lst);
        // The pixels whose last contributor lies at or behind list position j.
        const unsigned live = laneBits(lst > j);
        if (live == 0) continue;
        const Vf fx = centres.chunk(c);
        const Vf power = lanePower(p, fx, dy);
        unsigned bits = laneBits(~(power < p.skip)) & live;
        if (bits == 0) continue;
        if (__builtin_popcount(bits) < kMinVectorPixels) {
          storeVf(power_of, power);
          storeVf(G_of, expLanes(power));
          for (; bits != 0; bits &= bits - 1) {  // unblendGaussian, pixel by pixel
            const int k = lowestLane(bits), l = base + k;
            bool clamped;
            const float G = G_of[k];
            const float alpha = alphaOne(p, power_of[k], G, &clamped);
            if (alpha == 0.f) continue;
            if (!row_loaded) {
              std::memcpy(gb, gj, sizeof(float) * grad_row);
              row_loaded = true;
            }
            st.trans[l] = st.trans[l] / (1.f - alpha);
            const float w = alpha * st.trans[l];
            const float* gpix = gimg + (pix0 + l) * D;
            float dot = 0.f;
            for (int64_t ch = 0; ch < D; ++ch) dot += v[ch] * gpix[ch];
            addValues<kD>(gb + 6, gpix, w, D);
            st.behind[l] =
                st.last_alpha[l] * st.last_dot[l] + (1.f - st.last_alpha[l]) * st.behind[l];
            float g_a = (dot - st.behind[l]) * st.trans[l];
            g_a += st.g_out[l] * st.final_trans[l] / (1.f - alpha);
            st.last_dot[l] = dot;
            st.last_alpha[l] = alpha;
            if (clamped) continue;  // alpha = kMaxAlpha does not depend on the Gaussian
            gb[5] += G * g_a;
            const float g_power = p.opacity * G * g_a;
            const float dx = p.mean2d[0] - centres.fx[l];
            gb[0] += -g_power * (p.conic[0] * dx + p.conic[1] * dy);
            gb[1] += -g_power * (p.conic[2] * dy + p.conic[1] * dx);
            gb[2] += -0.5f * dx * dx * g_power;
            gb[3] += -dx * dy * g_power;
            gb[4] += -0.5f * dy * dy * g_power;
          }
          continue;
        }
        // unblendGaussian on every lane of the chunk.
        Vi candidate;
        for (int k = 0; k < kW; ++k) candidate[k] = (bits >> k) & 1u ? -1 : 0;
        const LaneAlpha a = alphaLanes(p, power);
        const Vi m = candidate & (a.alpha != 0.f);
        unsigned m_bits = laneBits(m);
        if (m_bits == 0) continue;
        if (!row_loaded) {
          std::memcpy(gb, gj, sizeof(float) * grad_row);
          row_loaded = true;
        }
        const Vf one_minus = 1.f - a.alpha;
        const Vf tr = loadVf(st.trans + base);
        const Vf trans_j = tr / one_minus;
        storeVf(st.trans + base, m ? trans_j : tr);
        const Vf w = a.alpha * trans_j;
        Vf dot = Vf{};
        if (!by_channel) {
          for (int64_t ch = 0; ch < D; ++ch) {
            for (int l = 0; l < kRow; ++l)
              g_by_channel[ch * kRow + l] = l < lanes ? gimg[(pix0 + l) * D + ch] : 0.f;
          }
          by_channel = true;
        }
        for (int64_t ch = 0; ch < D; ++ch) dot += v[ch] * loadVf(g_by_channel + ch * kRow + base);
        const Vf la = loadVf(st.last_alpha + base), ld = loadVf(st.last_dot + base);
        const Vf bh = loadVf(st.behind + base);
        const Vf behind_j = la * ld + (1.f - la) * bh;
        storeVf(st.behind + base, m ? behind_j : bh);
        Vf g_a = (dot - behind_j) * trans_j;
        g_a += loadVf(st.g_out + base) * loadVf(st.final_trans + base) / one_minus;
        storeVf(st.last_dot + base, m ? dot : ld);
        storeVf(st.last_alpha + base, m ? a.alpha : la);
        // pixelAlphaBackward on every lane.
        const Vf g_power = p.opacity * a.G * g_a;
        const Vf dx = p.mean2d[0] - fx;
        storeVf(w_of, w);
        storeVf(g_opacity_of, a.G * g_a);
        storeVf(g_mean_x_of, -g_power * (p.conic[0] * dx + p.conic[1] * dy));
        storeVf(g_mean_y_of, -g_power * (p.conic[2] * dy + p.conic[1] * dx));
        storeVf(g_conic0_of, -0.5f * dx * dx * g_power);
        storeVf(g_conic1_of, -dx * dy * g_power);
        storeVf(g_conic2_of, -0.5f * dy * dy * g_power);
        std::memcpy(clamped_of, &a.clamped, sizeof clamped_of);
        // The chunk's additions to Gaussian j's gradients, in pixel order.
        for (; m_bits != 0; m_bits &= m_bits - 1) {
          const int k = lowestLane(m_bits);
          addValues<kD>(gb + 6, gimg + (pix0 + base + k) * D, w_of[k], D);
          if (clamped_of[k] != 0) continue;
          gb[5] += g_opacity_of[k];
          gb[0] += g_mean_x_of[k];
          gb[1] += g_mean_y_of[k];
          gb[2] += g_conic0_of[k];
          gb[3] += g_conic1_of[k];
          gb[4] += g_conic2_of[k];
        }
      }
      if (row_loaded) std::memcpy(gj, gb, sizeof(float) * grad_row);
    }
  }
}

}  // namespace

void forwardTile(const TileView& tile, float* accum, float* img, float* alpha_out, int* last_out) {
  if (tile.D == 3) {
    forwardRows<3>(tile, accum, img, alpha_out, last_out);
  } else {
    forwardRows<0>(tile, accum, img, alpha_out, last_out);
  }
}

void backwardTile(const TileView& tile, const float* gimg, const float* galpha,
                  const float* alpha_fwd, const int* last_fwd, float* scratch, float* grads) {
  if (tile.D == 3) {
    backwardRows<3>(tile, gimg, galpha, alpha_fwd, last_fwd, scratch, grads);
  } else {
    backwardRows<0>(tile, gimg, galpha, alpha_fwd, last_fwd, scratch, grads);
  }
}

}  // namespace SADSPLAT_LANES_NS
}  // namespace cpu_lanes
}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
