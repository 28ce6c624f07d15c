#pragma once
/// \file adam.h
/// \brief Adam (Kingma & Ba) as the trainer uses it: one fused, in-place step per tensor (a
/// single pass over value, gradient and moments; one kernel on CUDA) instead of the eight
/// element-wise operations of the textbook formula. The moments are plain tensors that the
/// trainer reshapes when densification adds or removes Gaussians.

#include <ATen/ATen.h>

#include <cstdint>
#include <vector>

namespace sadsplat {
namespace gaussians {

/// \brief Adam's constants (3DGS uses eps = 1e-15).
struct AdamSettings {
  double beta1 = 0.9;
  double beta2 = 0.999;
  double eps = 1e-15;
};

/// \brief One Adam step, in place:
/// m = b1 m + (1 - b1) g;  v = b2 v + (1 - b2) g^2;
/// value -= lr (m / (1 - b1^step)) / (sqrt(v / (1 - b2^step)) + eps).
/// \param[in,out] value float32 (or float64 on the CPU) tensor, contiguous
/// \param[in] grad same shape, or undefined for a zero gradient (the moments decay and the
///   value still moves by its momentum)
/// \param[in,out] m, v first and second moments, same shape, dtype and device as `value`
/// \param[in] lr learning rate; \param[in] step 1-based step count of the bias correction
/// \throws sadsplat::Error when shapes, dtypes or devices differ
void adamStep(at::Tensor& value, const at::Tensor& grad, at::Tensor& m, at::Tensor& v, double lr,
              std::int64_t step, const AdamSettings& settings = AdamSettings());

/// \brief One tensor of adamSteps(): the arguments of adamStep() but the step and settings.
struct AdamTensors {
  at::Tensor value, grad, m, v;
  double lr = 0;
};

/// \brief adamStep() for several tensors at one step count: the same values as one adamStep()
/// per tensor; on CUDA (float32, one device) one kernel launch for up to 16 tensors instead of
/// one per tensor.
void adamSteps(std::vector<AdamTensors>& tensors, std::int64_t step,
               const AdamSettings& settings = AdamSettings());

}  // namespace gaussians
}  // namespace sadsplat
