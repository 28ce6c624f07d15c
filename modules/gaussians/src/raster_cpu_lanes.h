#pragma once
// The CPU rasterizer's tile loops with a tile row's 16 pixels in the lanes of one vector: per
// Gaussian the skip test, the alpha (its exp included: expPoly, lane by lane), the transmittance
// and, in the backward, the whole per-pixel recurrence run for the row's 16 pixels at once; the
// channel sums and the additions to a Gaussian's gradient row stay per pixel, in pixel order. Every
// lane does the float operations of the scalar loops (raster_cpu_tiles.h) in the same order, so
// images and gradients are bit-identical to them (test_raster_cpu_paths.cpp).
//
// Compiled once per instruction set (raster_cpu_lanes_avx2.cpp, raster_cpu_lanes_avx512.cpp, with
// -ffp-contract=off so that no multiply-add is fused) and called only where the CPU has that set
// (lanesAvailable). The loops take plain arrays: nothing inline from a shared header is
// instantiated in those translation units, whose copies would carry instructions the baseline
// build must not run.

#include <cstdint>

#include "raster_cpu_tiles.h"

namespace sadsplat {
namespace gaussians {
namespace raster {
namespace cpu_lanes {

/// One tile's list as the lane loops read it (a TileList<float>'s arrays) and where it lies.
struct TileView {
  const cpu_tiles::PackedGaussian<float>* gaussians;
  const float* values;  ///< [count, D]
  int count;
  int64_t D;
  int tx, ty, width, height;
};

/// Floats of scratch the backward needs: the pixel gradients of a tile row as [D][16] and one
/// gradient row (6 + D).
inline int64_t backwardScratchFloats(int64_t D) { return 16 * D + 6 + D; }

enum class Isa { kAvx2, kAvx512 };

/// Whether this build has the loops for `isa` and this CPU (and its operating system) runs them.
bool lanesAvailable(Isa isa);

/// forwardTileRows / backwardTileRows of raster_cpu_tiles.h, with the row's pixels in lanes.
/// accum: kTileSize * D floats; scratch: backwardScratchFloats(D) floats.
void forwardTileLanes(Isa isa, const TileView& tile, float* accum, float* img, float* alpha_out,
                      int* last_out);
void backwardTileLanes(Isa isa, const TileView& tile, const float* gimg, const float* galpha,
                       const float* alpha_fwd, const int* last_fwd, float* scratch, float* grads);

// One instruction set's loops (defined in its own translation unit).
#define SADSPLAT_DECLARE_LANES(ns)                                                              \
  namespace ns {                                                                                \
  void forwardTile(const TileView& tile, float* accum, float* img, float* alpha_out,            \
                   int* last_out);                                                              \
  void backwardTile(const TileView& tile, const float* gimg, const float* galpha,               \
                    const float* alpha_fwd, const int* last_fwd, float* scratch, float* grads); \
  }
SADSPLAT_DECLARE_LANES(avx2)
SADSPLAT_DECLARE_LANES(avx512)
#undef SADSPLAT_DECLARE_LANES

}  // namespace cpu_lanes
}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
