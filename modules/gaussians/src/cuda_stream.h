#pragma once
// Internal: the current CUDA stream of a tensor's device, as the untyped handle the .cu
// backends take (their interfaces name no CUDA type, so the .cpp files need no CUDA headers).

#if SADSPLAT_HAVE_CUDA
#include <ATen/ATen.h>
#include <c10/cuda/CUDAStream.h>

namespace sadsplat {
namespace gaussians {

/// LibTorch's current stream on the tensor's device (which a guard in the caller makes current).
inline void* currentStream(const at::Tensor& t) {
  return static_cast<void*>(c10::cuda::getCurrentCUDAStream(t.device().index()).stream());
}

}  // namespace gaussians
}  // namespace sadsplat
#endif
