#pragma once
// One element of the fused Adam step, shared by the CPU loop (adam.cpp) and the CUDA kernel
// (adam_cuda.cu). The order of operations is the textbook formula's, so both backends round
// alike.

#if defined(__CUDACC__)
#define SADSPLAT_ADAM_HD __host__ __device__ __forceinline__
#else
#define SADSPLAT_ADAM_HD inline
#endif

#include <cmath>
#include <cstdint>

namespace sadsplat {
namespace gaussians {
namespace adam {

/// Per-step constants: the betas, their complements, the bias corrections and lr.
template <typename T>
struct Coefficients {
  T beta1, one_minus_beta1, beta2, one_minus_beta2, correction1, correction2, eps, lr;
};

/// The constants of step `step` (>= 1) for learning rate lr and Adam's beta1, beta2, eps.
template <typename T>
inline Coefficients<T> coefficientsAt(std::int64_t step, double lr, double beta1, double beta2,
                                      double eps) {
  const double k = static_cast<double>(step);
  return {T(beta1),
          T(1 - beta1),
          T(beta2),
          T(1 - beta2),
          T(1 - std::pow(beta1, k)),
          T(1 - std::pow(beta2, k)),
          T(eps),
          T(lr)};
}

template <typename T>
SADSPLAT_ADAM_HD void update(T* value, T grad, T* m, T* v, const Coefficients<T>& c) {
  const T m_new = *m * c.beta1 + grad * c.one_minus_beta1;
  const T v_new = *v * c.beta2 + grad * grad * c.one_minus_beta2;
  *m = m_new;
  *v = v_new;
  *value -= c.lr * ((m_new / c.correction1) / (std::sqrt(v_new / c.correction2) + c.eps));
}

/// The tensors of one multi-tensor launch on CUDA (passed by value as the kernel's argument).
constexpr int kMaxBatch = 16;
struct StepBatch {
  float* value[kMaxBatch];
  const float* grad[kMaxBatch];  // null: a zero gradient
  float* m[kMaxBatch];
  float* v[kMaxBatch];
  std::int64_t n[kMaxBatch];
  Coefficients<float> c[kMaxBatch];
  int count = 0;
};

}  // namespace adam
}  // namespace gaussians
}  // namespace sadsplat
