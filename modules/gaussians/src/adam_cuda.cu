// The fused Adam step on CUDA: one thread per element (adam_math.h holds the arithmetic).
#include <ATen/ATen.h>
#include <cuda_runtime.h>

#include "adam_math.h"
#include "sadsplat/common/cuda_support.h"

namespace sadsplat {
namespace gaussians {
namespace adam {
namespace {

__global__ void stepKernel(float* value, const float* grad, float* m, float* v, int64_t n,
                           Coefficients<float> c) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  update(value + i, grad != nullptr ? grad[i] : 0.0f, m + i, v + i, c);
}

// One launch for several tensors: blockIdx.y picks the tensor, blocks stride over its elements.
__global__ void stepManyKernel(StepBatch batch) {
  const int k = blockIdx.y;
  const int64_t n = batch.n[k];
  float* value = batch.value[k];
  const float* grad = batch.grad[k];
  float* m = batch.m[k];
  float* v = batch.v[k];
  const Coefficients<float> c = batch.c[k];
  for (int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x; i < n;
       i += static_cast<int64_t>(gridDim.x) * blockDim.x) {
    update(value + i, grad != nullptr ? grad[i] : 0.0f, m + i, v + i, c);
  }
}

}  // namespace

void stepManyCuda(const StepBatch& batch, void* stream_ptr) {
  if (batch.count == 0) return;
  constexpr int kThreads = 256, kMaxBlocks = 1024;
  int64_t largest = 0;
  for (int k = 0; k < batch.count; ++k) largest = batch.n[k] > largest ? batch.n[k] : largest;
  if (largest == 0) return;
  const int64_t blocks = (largest + kThreads - 1) / kThreads;
  const dim3 grid(static_cast<unsigned>(blocks < kMaxBlocks ? blocks : kMaxBlocks),
                  static_cast<unsigned>(batch.count));
  stepManyKernel<<<grid, kThreads, 0, static_cast<cudaStream_t>(stream_ptr)>>>(batch);
  checkCudaLaunch("<adam>", "stepManyKernel");
}

void stepCuda(at::Tensor& value, const at::Tensor& grad, at::Tensor& m, at::Tensor& v,
              const Coefficients<float>& c, void* stream_ptr) {
  const int64_t n = value.numel();
  if (n == 0) return;
  constexpr int kThreads = 256;
  const int64_t blocks = (n + kThreads - 1) / kThreads;
  stepKernel<<<static_cast<unsigned>(blocks), kThreads, 0, static_cast<cudaStream_t>(stream_ptr)>>>(
      value.data_ptr<float>(), grad.defined() ? grad.data_ptr<float>() : nullptr,
      m.data_ptr<float>(), v.data_ptr<float>(), n, c);
  checkCudaLaunch("<adam>", "stepKernel");
}

}  // namespace adam
}  // namespace gaussians
}  // namespace sadsplat
