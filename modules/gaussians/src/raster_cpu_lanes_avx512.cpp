// The lane loops (raster_cpu_lanes_impl.h) for AVX-512 (F): compiled with -mavx512f
// -ffp-contract=off, called only where the CPU has AVX-512 (raster_cpu_lanes.cpp).
#if defined(SADSPLAT_CPU_LANES_AVX512)
#define SADSPLAT_LANES_NS avx512
#include "raster_cpu_lanes_impl.h"
#endif
