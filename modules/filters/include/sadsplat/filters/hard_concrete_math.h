#pragma once
/// \file hard_concrete_math.h
/// \brief The scalar Hard Concrete math the drop filters need (no LibTorch): the gate's
/// parameters, its probability of being non-zero and the paper's drop rule. The tensor versions
/// used in training are in sadsplat/semantic_drop/hard_concrete.h.
///
/// A gate z in [0, 1] per Gaussian: u ~ U(0, 1), s = sigmoid((log u - log(1 - u) + log_alpha) /
/// beta), z = clamp(s (r - l) + l, 0, 1), with (l, r) = (-0.1, 1.1) (Louizos et al. 2018). Its
/// probability of being non-zero has the closed form P(z > 0) = sigmoid(log_alpha - beta *
/// logit(t)), t = -l / (r - l). The paper prints sigmoid((log_alpha - beta logit(t)) / beta); that
/// equals the sampler's probability only for beta = 1, so sadsplat uses the form that matches the
/// sampler (a test checks it empirically).

namespace sadsplat {
namespace filters {

/// \brief Parameters of the gate; defaults from Louizos et al.
struct HardConcreteParams {
  double beta = 2.0 / 3.0;  ///< temperature
  double l = -0.1;          ///< stretch interval lower bound
  double r = 1.1;           ///< stretch interval upper bound
};

/// \brief logit(t), t = -l / (r - l): where the stretched sample crosses 0.
double logitOfThreshold(const HardConcreteParams& p);

/// \brief P(z > 0) for one log_alpha.
double probabilityNonZero(double log_alpha, const HardConcreteParams& p = {});

/// \brief P_drop = clamp(p_base (1 - confidence) (1 - P_nonzero), 0, 1) (paper, drop rule); a mode
/// without the semantic term uses confidence = 0, one without the structure term P_learned = 1.
double dropProbability(double p_base, double confidence, double log_alpha, bool use_confidence,
                       bool use_structure, const HardConcreteParams& p = {});

}  // namespace filters
}  // namespace sadsplat
