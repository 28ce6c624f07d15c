// The balanced drop rule's L0 force on CUDA (l0_force.h): the two sums over the reached
// Gaussians (double, one atomic per block), then the update in place.
#include <ATen/ATen.h>
#include <cuda_runtime.h>

#include "sadsplat/common/cuda_support.h"

namespace sadsplat {
namespace semantic_drop {
namespace l0_force {
namespace {

constexpr int kThreads = 256;
constexpr int kMaxSumBlocks = 1024;

__device__ __forceinline__ double warpSum(double v) {
  for (int offset = 16; offset > 0; offset >>= 1) v += __shfl_down_sync(0xffffffffu, v, offset);
  return v;
}

// sums[0] += sum |grad| over reached Gaussians, sums[1] += sum direction over them.
__global__ void sumsKernel(int64_t n, const float* __restrict__ grad,
                           const float* __restrict__ direction,
                           const float* __restrict__ opacity_grad, double* sums) {
  double rgb = 0, l0 = 0;
  for (int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<int64_t>(gridDim.x) * blockDim.x) {
    if (opacity_grad[i] != 0.f) {
      rgb += fabsf(grad[i]);
      l0 += direction[i];
    }
  }
  __shared__ double s_rgb[kThreads / 32], s_l0[kThreads / 32];
  rgb = warpSum(rgb);
  l0 = warpSum(l0);
  const int warp = threadIdx.x / 32, lane = threadIdx.x % 32;
  if (lane == 0) {
    s_rgb[warp] = rgb;
    s_l0[warp] = l0;
  }
  __syncthreads();
  if (warp != 0) return;
  rgb = lane < kThreads / 32 ? s_rgb[lane] : 0.0;
  l0 = lane < kThreads / 32 ? s_l0[lane] : 0.0;
  rgb = warpSum(rgb);
  l0 = warpSum(l0);
  if (lane == 0) {
    atomicAdd(&sums[0], rgb);
    atomicAdd(&sums[1], l0);
  }
}

__global__ void applyKernel(int64_t n, float* grad, const float* __restrict__ direction,
                            const float* __restrict__ opacity_grad,
                            const float* __restrict__ weights, float strength,
                            const double* __restrict__ sums) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n || opacity_grad[i] == 0.f) return;
  const float l0 = static_cast<float>(sums[1]);
  if (!(l0 > 0.f)) return;
  const float scale = static_cast<float>(sums[0]) / fmaxf(l0, 1e-30f);
  float force = direction[i] * (strength * scale);
  if (weights != nullptr) force *= weights[i];
  grad[i] += force;
}

}  // namespace

void addCuda(float* grad, const float* direction, const float* opacity_grad, const float* weights,
             std::int64_t n, float strength, double* sums, void* stream_ptr) {
  cudaStream_t stream = static_cast<cudaStream_t>(stream_ptr);
  if (n == 0) return;
  const int64_t blocks = (n + kThreads - 1) / kThreads;
  cudaMemsetAsync(sums, 0, 2 * sizeof(double), stream);
  sumsKernel<<<static_cast<unsigned>(blocks < kMaxSumBlocks ? blocks : kMaxSumBlocks), kThreads, 0,
               stream>>>(n, grad, direction, opacity_grad, sums);
  checkCudaLaunch("<L0 force>", "sumsKernel");
  applyKernel<<<static_cast<unsigned>(blocks), kThreads, 0, stream>>>(
      n, grad, direction, opacity_grad, weights, strength, sums);
  checkCudaLaunch("<L0 force>", "applyKernel");
}

}  // namespace l0_force
}  // namespace semantic_drop
}  // namespace sadsplat
