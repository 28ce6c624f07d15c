// The Hard Concrete training gate on CUDA: noise, gate and its gradient in one kernel each, one
// thread per Gaussian (hard_concrete_backend.h).
#include <cuda_runtime.h>

#include "hard_concrete_backend.h"
#include "sadsplat/common/cuda_support.h"

namespace sadsplat {
namespace semantic_drop {
namespace hard_concrete_fused {
namespace {

constexpr int kThreads = 256;

// The stretched sample s (r - l) + l before the clamp, and s.
__device__ __forceinline__ float stretched(float log_alpha, int64_t i, const GateParams& p,
                                          float* s_out) {
  const float u = fminf(fmaxf(gaussians::counterUniformAt(p.key, i), 1e-6f), 1.f - 1e-6f);
  const float x = (logf(u) - logf(1.f - u) + log_alpha) * p.inv_beta;
  const float s = 1.f / (1.f + expf(-x));
  *s_out = s;
  return s * (p.r - p.l) + p.l;
}

__global__ void forwardKernel(const float* __restrict__ log_alpha, int64_t n, GateParams p,
                              float* gate) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float s;
  gate[i] = fminf(fmaxf(stretched(log_alpha[i], i, p, &s), 0.f), 1.f);
}

__global__ void backwardKernel(const float* __restrict__ log_alpha,
                               const float* __restrict__ grad_gate, int64_t n, GateParams p,
                               float* grad_log_alpha) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float s;
  const float z = stretched(log_alpha[i], i, p, &s);
  // The clamp passes the gradient on [0, 1] (its bounds included), as ATen's clamp does, and
  // below 0 too with closed_gradient.
  const bool inside = (p.closed_gradient || z >= 0.f) && z <= 1.f;
  grad_log_alpha[i] = inside ? grad_gate[i] * (p.r - p.l) * s * (1.f - s) * p.inv_beta : 0.f;
}

void check(const char* kernel) { checkCudaLaunch("<hard concrete gate>", kernel); }

unsigned blocks(int64_t n) { return static_cast<unsigned>((n + kThreads - 1) / kThreads); }

}  // namespace

void forwardCuda(const float* log_alpha, std::int64_t n, const GateParams& p, float* gate,
                 void* stream) {
  if (n == 0) return;
  forwardKernel<<<blocks(n), kThreads, 0, static_cast<cudaStream_t>(stream)>>>(log_alpha, n, p,
                                                                               gate);
  check("forwardKernel");
}

void backwardCuda(const float* log_alpha, const float* grad_gate, std::int64_t n,
                  const GateParams& p, float* grad_log_alpha, void* stream) {
  if (n == 0) return;
  backwardKernel<<<blocks(n), kThreads, 0, static_cast<cudaStream_t>(stream)>>>(
      log_alpha, grad_gate, n, p, grad_log_alpha);
  check("backwardKernel");
}

}  // namespace hard_concrete_fused
}  // namespace semantic_drop
}  // namespace sadsplat
