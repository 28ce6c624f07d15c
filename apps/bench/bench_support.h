#pragma once
// What the benchmark programs share: waiting for the device before reading the clock.

#include <c10/core/Device.h>

#if SADSPLAT_HAVE_CUDA
#include <cuda_runtime_api.h>
#endif

namespace sadsplat {
namespace bench {

inline void synchronize(const c10::Device& device) {
#if SADSPLAT_HAVE_CUDA
  if (device.is_cuda()) cudaDeviceSynchronize();
#endif
  (void)device;
}

}  // namespace bench
}  // namespace sadsplat
