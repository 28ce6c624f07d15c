#pragma once
/// \file hard_concrete.h
/// \brief The Hard Concrete gate of the learnable structure drop (paper, "Learnable Structure
/// Drop Module"; Louizos et al. 2018), as scalar functions (for PCL filters) and tensor
/// functions (for training).
///
/// A gate z in [0, 1] per Gaussian: u ~ U(0, 1), s = sigmoid((log u - log(1 - u) + log_alpha) /
/// beta), z = clamp(s (r - l) + l, 0, 1), with (l, r) = (-0.1, 1.1). Its probability of being
/// non-zero has the closed form P(z > 0) = sigmoid(log_alpha - beta * logit(t)), t = -l / (r - l).
/// The paper prints sigmoid((log_alpha - beta logit(t)) / beta); that equals the sampler's
/// probability only for beta = 1, so sadsplat uses the form that matches the sampler (a test checks
/// it empirically).

#include <ATen/ATen.h>

#include <cstdint>

namespace sadsplat {
namespace semantic_drop {

/// \brief Parameters of the gate; defaults from Louizos et al.
struct HardConcreteParams {
  double beta = 2.0 / 3.0;  ///< temperature
  double l = -0.1;          ///< stretch interval lower bound
  double r = 1.1;           ///< stretch interval upper bound
};

/// \brief P(z > 0) for one log_alpha.
double probabilityNonZero(double log_alpha, const HardConcreteParams& p = {});
/// \brief P(z > 0) for a tensor of log_alphas (differentiable).
at::Tensor probabilityNonZero(const at::Tensor& log_alpha, const HardConcreteParams& p = {});
/// \brief A sample of gates for `log_alpha` (differentiable in log_alpha) from `uniform` noise
/// in (0, 1) of the same shape.
at::Tensor sampleGate(const at::Tensor& log_alpha, const at::Tensor& uniform,
                      const HardConcreteParams& p = {});
/// \brief sampleGate with the trainer's counter-based noise, counterUniform(n, seed, purpose,
/// iteration) (sadsplat/gaussians/counter_random.h). On CUDA (float32) the noise, the gate and
/// its gradient come from one kernel each (nothing but log_alpha kept for the backward pass);
/// elsewhere sampleGate(log_alpha, counterUniform(...)).
at::Tensor sampleCounterGate(const at::Tensor& log_alpha, std::uint64_t seed,
                             std::uint64_t purpose, std::uint64_t iteration,
                             const HardConcreteParams& p = {});
/// \brief Whether sampleCounterGate takes the fused path for this tensor.
bool counterGateIsFused(const at::Tensor& log_alpha);
/// \brief The deterministic gate used at evaluation: clamp(sigmoid(log_alpha) (r - l) + l, 0, 1).
at::Tensor deterministicGate(const at::Tensor& log_alpha, const HardConcreteParams& p = {});

/// \brief P_drop = clamp(p_base (1 - confidence) (1 - P_nonzero), 0, 1) (paper, drop rule); a mode
/// without the semantic term uses confidence = 0, one without the structure term P_learned = 1.
double dropProbability(double p_base, double confidence, double log_alpha, bool use_confidence,
                       bool use_structure, const HardConcreteParams& p = {});

}  // namespace semantic_drop
}  // namespace sadsplat
