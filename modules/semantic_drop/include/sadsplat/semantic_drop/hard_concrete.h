#pragma once
/// \file hard_concrete.h
/// \brief The Hard Concrete gate of the learnable structure drop (paper, "Learnable Structure
/// Drop Module"; Louizos et al. 2018) as tensor functions for training; the scalar functions
/// of the PCL filters are in sadsplat/filters/hard_concrete_math.h.
///
/// A gate z in [0, 1] per Gaussian: u ~ U(0, 1), s = sigmoid((log u - log(1 - u) + log_alpha) /
/// beta), z = clamp(s (r - l) + l, 0, 1), with (l, r) = (-0.1, 1.1). Its probability of being
/// non-zero has the closed form P(z > 0) = sigmoid(log_alpha - beta * logit(t)), t = -l / (r - l).
/// The paper prints sigmoid((log_alpha - beta logit(t)) / beta); that equals the sampler's
/// probability only for beta = 1, so sadsplat uses the form that matches the sampler (a test checks
/// it empirically).

#include <ATen/ATen.h>

#include <cstdint>

#include "sadsplat/filters/hard_concrete_math.h"

namespace sadsplat {
namespace semantic_drop {

// The scalar math lives in the torch-free filters layer.
using filters::dropProbability;
using filters::HardConcreteParams;
using filters::probabilityNonZero;
/// \brief P(z > 0) for a tensor of log_alphas (differentiable).
at::Tensor probabilityNonZero(const at::Tensor& log_alpha, const HardConcreteParams& p = {});
/// \brief A sample of gates for `log_alpha` (differentiable in log_alpha) from `uniform` noise
/// in (0, 1) of the same shape. The clamp passes no gradient where it closes a gate (z = 0)
/// unless `closed_gradient` (not the paper; for gradients of closed gates,
/// gaussians::RenderSettings::closed_gate_gradients): then the gradient is that of
/// s (r - l) + l there, a straight-through estimator at 0.
at::Tensor sampleGate(const at::Tensor& log_alpha, const at::Tensor& uniform,
                      const HardConcreteParams& p = {}, bool closed_gradient = false);
/// \brief sampleGate with the trainer's counter-based noise, counterUniform(n, seed, purpose,
/// iteration) (sadsplat/gaussians/counter_random.h). On CUDA (float32) the noise, the gate and
/// its gradient come from one kernel each (nothing but log_alpha kept for the backward pass);
/// elsewhere sampleGate(log_alpha, counterUniform(...)).
at::Tensor sampleCounterGate(const at::Tensor& log_alpha, std::uint64_t seed, std::uint64_t purpose,
                             std::uint64_t iteration, const HardConcreteParams& p = {},
                             bool closed_gradient = false);
/// \brief Whether sampleCounterGate takes the fused path for this tensor.
bool counterGateIsFused(const at::Tensor& log_alpha);
/// \brief The deterministic gate used at evaluation: clamp(sigmoid(log_alpha) (r - l) + l, 0, 1).
at::Tensor deterministicGate(const at::Tensor& log_alpha, const HardConcreteParams& p = {});

}  // namespace semantic_drop
}  // namespace sadsplat
