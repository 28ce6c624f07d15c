#include "sadsplat/gaussians/adam.h"

#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAGuard.h>
#include <c10/cuda/CUDAStream.h>
#endif

#include "adam_math.h"
#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {
namespace adam {
#if SADSPLAT_HAVE_CUDA
void stepCuda(at::Tensor& value, const at::Tensor& grad, at::Tensor& m, at::Tensor& v,
              const Coefficients<float>& c, void* stream);
void stepManyCuda(const StepBatch& batch, void* stream);
#endif
}  // namespace adam

namespace {

void expectLike(const at::Tensor& t, const at::Tensor& value, const char* name) {
  if (!t.defined() || !t.sizes().equals(value.sizes()) || t.scalar_type() != value.scalar_type() ||
      t.device() != value.device() || !t.is_contiguous()) {
    throw Error("<adam>", name, "a contiguous tensor shaped, typed and placed like the value",
                "another shape, type, device or layout");
  }
}

template <typename T>
adam::Coefficients<T> coefficients(double lr, std::int64_t step, const AdamSettings& s) {
  return adam::coefficientsAt<T>(step, lr, s.beta1, s.beta2, s.eps);
}

// Elements [begin, end) of a float step, four at a time with SSE where the build has it: the same
// operations in the same order as adam::update (SSE's division and square root round exactly as
// the scalar ones do and x86-64's baseline has no FMA to contract them), so every element is
// bit-identical to the scalar loop's; four times fewer divisions and square roots to wait on.
void updateFloats(float* x, const float* g, float* m, float* v, const adam::Coefficients<float>& c,
                  int64_t begin, int64_t end) {
  int64_t i = begin;
#if defined(__SSE2__)
  const __m128 beta1 = _mm_set1_ps(c.beta1), one_minus_beta1 = _mm_set1_ps(c.one_minus_beta1);
  const __m128 beta2 = _mm_set1_ps(c.beta2), one_minus_beta2 = _mm_set1_ps(c.one_minus_beta2);
  const __m128 correction1 = _mm_set1_ps(c.correction1), correction2 = _mm_set1_ps(c.correction2);
  const __m128 eps = _mm_set1_ps(c.eps), lr = _mm_set1_ps(c.lr);
  for (; i + 4 <= end; i += 4) {
    const __m128 grad = g ? _mm_loadu_ps(g + i) : _mm_setzero_ps();
    const __m128 m_new =
        _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(m + i), beta1), _mm_mul_ps(grad, one_minus_beta1));
    const __m128 v_new = _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(v + i), beta2),
                                    _mm_mul_ps(_mm_mul_ps(grad, grad), one_minus_beta2));
    _mm_storeu_ps(m + i, m_new);
    _mm_storeu_ps(v + i, v_new);
    const __m128 denominator = _mm_add_ps(_mm_sqrt_ps(_mm_div_ps(v_new, correction2)), eps);
    const __m128 step = _mm_mul_ps(lr, _mm_div_ps(_mm_div_ps(m_new, correction1), denominator));
    _mm_storeu_ps(x + i, _mm_sub_ps(_mm_loadu_ps(x + i), step));
  }
#endif
  for (; i < end; ++i) adam::update(x + i, g ? g[i] : 0.f, m + i, v + i, c);
}

template <typename T>
void updateRange(T* x, const T* g, T* m, T* v, const adam::Coefficients<T>& c, int64_t begin,
                 int64_t end) {
  for (int64_t i = begin; i < end; ++i) adam::update(x + i, g ? g[i] : T(0), m + i, v + i, c);
}

void updateRange(float* x, const float* g, float* m, float* v, const adam::Coefficients<float>& c,
                 int64_t begin, int64_t end) {
  updateFloats(x, g, m, v, c, begin, end);
}

}  // namespace

namespace {

// The arguments' checks of adamStep; returns the gradient, contiguous (or undefined).
at::Tensor checkedGradient(const at::Tensor& value, const at::Tensor& grad, const at::Tensor& m,
                           const at::Tensor& v, std::int64_t step) {
  if (!value.defined() || !value.is_contiguous()) {
    throw Error("<adam>", "value", "a defined, contiguous tensor",
                value.defined() ? "a non-contiguous tensor" : "an undefined tensor");
  }
  if (step < 1) throw Error("<adam>", "step", ">= 1", std::to_string(step));
  expectLike(m, value, "m");
  expectLike(v, value, "v");
  const at::Tensor g = grad.defined() ? grad.contiguous() : grad;
  if (g.defined()) expectLike(g, value, "grad");
  return g;
}

}  // namespace

void adamSteps(std::vector<AdamTensors>& tensors, std::int64_t step, const AdamSettings& settings) {
#if SADSPLAT_HAVE_CUDA
  const bool batched =
      !tensors.empty() && std::all_of(tensors.begin(), tensors.end(), [&](const AdamTensors& t) {
        return t.value.defined() && t.value.is_cuda() && t.value.scalar_type() == at::kFloat &&
               t.value.device() == tensors.front().value.device();
      });
  if (batched) {
    const c10::cuda::CUDAGuard guard(tensors.front().value.device());
    adam::StepBatch batch;
    std::vector<at::Tensor> grads;  // contiguous copies stay alive until the launch
    const auto launch = [&] {
      adam::stepManyCuda(batch, c10::cuda::getCurrentCUDAStream().stream());
      batch = adam::StepBatch();
      grads.clear();
    };
    for (AdamTensors& t : tensors) {
      grads.push_back(checkedGradient(t.value, t.grad, t.m, t.v, step));
      const int k = batch.count++;
      batch.value[k] = t.value.data_ptr<float>();  // updated outside autograd
      batch.grad[k] = grads.back().defined() ? grads.back().data_ptr<float>() : nullptr;
      batch.m[k] = t.m.data_ptr<float>();
      batch.v[k] = t.v.data_ptr<float>();
      batch.n[k] = t.value.numel();
      batch.c[k] = coefficients<float>(t.lr, step, settings);
      if (batch.count == adam::kMaxBatch) launch();
    }
    launch();
    return;
  }
#endif
  for (AdamTensors& t : tensors) adamStep(t.value, t.grad, t.m, t.v, t.lr, step, settings);
}

void adamStep(at::Tensor& value, const at::Tensor& grad, at::Tensor& m, at::Tensor& v, double lr,
              std::int64_t step, const AdamSettings& settings) {
  const at::Tensor g = checkedGradient(value, grad, m, v, step);
  // The update runs outside autograd: value is a leaf that requires grad.
  at::Tensor data = value.detach();
  if (value.is_cuda()) {
#if SADSPLAT_HAVE_CUDA
    if (value.scalar_type() != at::kFloat) {
      throw Error("<adam>", "value", "float32 on CUDA", c10::toString(value.scalar_type()));
    }
    const c10::cuda::CUDAGuard guard(value.device());
    adam::stepCuda(data, g, m, v, coefficients<float>(lr, step, settings),
                   c10::cuda::getCurrentCUDAStream().stream());
    return;
#else
    throw Error("<adam>", "device", "cpu (this build has no CUDA)", "cuda");
#endif
  }
  AT_DISPATCH_FLOATING_TYPES(value.scalar_type(), "adamStep", [&] {
    const adam::Coefficients<scalar_t> c = coefficients<scalar_t>(lr, step, settings);
    scalar_t* x = data.data_ptr<scalar_t>();
    scalar_t* mm = m.data_ptr<scalar_t>();
    scalar_t* vv = v.data_ptr<scalar_t>();
    const scalar_t* gg = g.defined() ? g.data_ptr<scalar_t>() : nullptr;
    at::parallel_for(0, value.numel(), 1 << 15, [&](int64_t begin, int64_t end) {
      updateRange(x, gg, mm, vv, c, begin, end);
    });
  });
}

}  // namespace gaussians
}  // namespace sadsplat
