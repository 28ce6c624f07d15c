// The lane loops (raster_cpu_lanes_impl.h) for AVX2: compiled with -mavx2 -ffp-contract=off, called
// only where the CPU has AVX2 (raster_cpu_lanes.cpp).
#if defined(SADSPLAT_CPU_LANES_AVX2)
#define SADSPLAT_LANES_NS avx2
#include "raster_cpu_lanes_impl.h"
#endif
