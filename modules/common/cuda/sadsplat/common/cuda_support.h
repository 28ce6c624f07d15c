#pragma once
/// \file cuda_support.h
/// \brief Internal (not installed): what the modules' CUDA backends share. The backends'
/// interfaces name no CUDA type, so the .cpp files pass streams as untyped handles.

#include "sadsplat/common/error.h"

#if defined(__CUDACC__)
#include <cuda_runtime.h>
#endif
#if SADSPLAT_HAVE_CUDA
#include <ATen/ATen.h>
#include <c10/cuda/CUDAStream.h>
#endif

namespace sadsplat {

#if defined(__CUDACC__)
/// \brief Throws sadsplat::Error naming `origin` (e.g. "<render>") and the kernel when the last
/// kernel launch of this thread failed.
inline void checkCudaLaunch(const char* origin, const char* kernel) {
  const cudaError_t err = cudaGetLastError();
  if (err != cudaSuccess) {
    throw Error(origin, kernel, "a successful CUDA kernel launch", cudaGetErrorString(err));
  }
}
#endif

#if SADSPLAT_HAVE_CUDA
/// \brief LibTorch's current stream on the tensor's device (which a guard in the caller makes
/// current), as the untyped handle the .cu backends take.
inline void* currentStream(const at::Tensor& t) {
  return static_cast<void*>(c10::cuda::getCurrentCUDAStream(t.device().index()).stream());
}
#endif

}  // namespace sadsplat
