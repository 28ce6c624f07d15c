// The densification statistics of one render on CUDA: one thread per Gaussian, in place.
#include <ATen/ATen.h>
#include <cuda_runtime.h>

#include "sadsplat/common/cuda_support.h"

namespace sadsplat {
namespace gaussians {
namespace densification_stats {
namespace {

__global__ void accumulateKernel(int64_t n, const float2* __restrict__ grad,
                                 const int* __restrict__ radii, float scale_x, float scale_y,
                                 float* grad_accum, float* denom, float* max_radii) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const int r = radii[i];
  if (r <= 0) return;
  const float2 g = grad[i];
  const float gx = g.x * scale_x, gy = g.y * scale_y;
  grad_accum[i] += sqrtf(gx * gx + gy * gy);
  denom[i] += 1.f;
  max_radii[i] = fmaxf(max_radii[i], static_cast<float>(r));
}

}  // namespace

void accumulateCuda(const at::Tensor& grad, const at::Tensor& radii, float scale_x, float scale_y,
                    at::Tensor& grad_accum, at::Tensor& denom, at::Tensor& max_radii,
                    void* stream) {
  const int64_t n = grad.size(0);
  if (n == 0) return;
  constexpr int kThreads = 256;
  const int64_t blocks = (n + kThreads - 1) / kThreads;
  accumulateKernel<<<static_cast<unsigned>(blocks), kThreads, 0,
                     static_cast<cudaStream_t>(stream)>>>(
      n, reinterpret_cast<const float2*>(grad.data_ptr<float>()), radii.data_ptr<int>(), scale_x,
      scale_y, grad_accum.data_ptr<float>(), denom.data_ptr<float>(), max_radii.data_ptr<float>());
  checkCudaLaunch("<densification statistics>", "accumulateKernel");
}

}  // namespace densification_stats
}  // namespace gaussians
}  // namespace sadsplat
