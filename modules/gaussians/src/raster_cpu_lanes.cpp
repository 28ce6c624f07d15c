// Which lane loops this build has and this CPU runs, and the calls into them.
#include "raster_cpu_lanes.h"

#include <stdexcept>

namespace sadsplat {
namespace gaussians {
namespace raster {
namespace cpu_lanes {

bool lanesAvailable(Isa isa) {
#if defined(SADSPLAT_CPU_LANES_AVX2) && defined(SADSPLAT_CPU_LANES_AVX512)
  // __builtin_cpu_supports also checks that the operating system saves the wider registers.
  static const bool avx2 = __builtin_cpu_supports("avx2");
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  return isa == Isa::kAvx2 ? avx2 : avx512;
#else
  (void)isa;
  return false;
#endif
}

void forwardTileLanes(Isa isa, const TileView& tile, float* accum, float* img, float* alpha_out,
                      int* last_out) {
  if (!lanesAvailable(isa)) throw std::logic_error("forwardTileLanes: instruction set not here");
#if defined(SADSPLAT_CPU_LANES_AVX2) && defined(SADSPLAT_CPU_LANES_AVX512)
  if (isa == Isa::kAvx512) {
    avx512::forwardTile(tile, accum, img, alpha_out, last_out);
  } else {
    avx2::forwardTile(tile, accum, img, alpha_out, last_out);
  }
#endif
}

void backwardTileLanes(Isa isa, const TileView& tile, const float* gimg, const float* galpha,
                       const float* alpha_fwd, const int* last_fwd, float* scratch, float* grads) {
  if (!lanesAvailable(isa)) throw std::logic_error("backwardTileLanes: instruction set not here");
#if defined(SADSPLAT_CPU_LANES_AVX2) && defined(SADSPLAT_CPU_LANES_AVX512)
  if (isa == Isa::kAvx512) {
    avx512::backwardTile(tile, gimg, galpha, alpha_fwd, last_fwd, scratch, grads);
  } else {
    avx2::backwardTile(tile, gimg, galpha, alpha_fwd, last_fwd, scratch, grads);
  }
#endif
}

}  // namespace cpu_lanes
}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
