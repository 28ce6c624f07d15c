#pragma once
// Internal interface of the fused Hard Concrete training gate (hard_concrete.cpp <->
// hard_concrete_cuda.cu): per Gaussian i, u = counterUniformAt(key, i) clamped to
// [1e-6, 1 - 1e-6], s = sigmoid((log u - log(1 - u) + log_alpha) / beta), z = clamp(s (r - l) + l,
// 0, 1); the backward recomputes u and s (nothing stored but log_alpha). With closed_gradient the
// gradient also passes where the clamp closes the gate (s (r - l) + l < 0).

#include <cstdint>

#include "sadsplat/gaussians/counter_hash.h"

namespace sadsplat {
namespace semantic_drop {
namespace hard_concrete_fused {

struct GateParams {
  gaussians::CounterKey key;
  float inv_beta = 1.5f;
  float l = -0.1f;
  float r = 1.1f;
  bool closed_gradient = false;
};

#if SADSPLAT_COMPILE_CUDA
/// gate[i] for n float32 log_alphas on the device; stream a cudaStream_t.
void forwardCuda(const float* log_alpha, std::int64_t n, const GateParams& p, float* gate,
                 void* stream);
/// grad_log_alpha[i] = grad_gate[i] * d gate[i] / d log_alpha[i].
void backwardCuda(const float* log_alpha, const float* grad_gate, std::int64_t n,
                  const GateParams& p, float* grad_log_alpha, void* stream);
#endif

}  // namespace hard_concrete_fused
}  // namespace semantic_drop
}  // namespace sadsplat
