#include "sadsplat/semantic_drop/hard_concrete.h"

#include <algorithm>
#include <cmath>

namespace sadsplat {
namespace semantic_drop {
namespace {

double logitOfThreshold(const HardConcreteParams& p) {
  const double t = -p.l / (p.r - p.l);
  return std::log(t / (1 - t));
}

}  // namespace

double probabilityNonZero(double log_alpha, const HardConcreteParams& p) {
  return 1.0 / (1.0 + std::exp(-(log_alpha - p.beta * logitOfThreshold(p))));
}

at::Tensor probabilityNonZero(const at::Tensor& log_alpha, const HardConcreteParams& p) {
  return at::sigmoid(log_alpha - p.beta * logitOfThreshold(p));
}

at::Tensor sampleGate(const at::Tensor& log_alpha, const at::Tensor& uniform,
                      const HardConcreteParams& p) {
  const at::Tensor u = uniform.clamp(1e-6, 1 - 1e-6);
  const at::Tensor s = at::sigmoid((at::log(u) - at::log(1 - u) + log_alpha) / p.beta);
  return (s * (p.r - p.l) + p.l).clamp(0, 1);
}

at::Tensor deterministicGate(const at::Tensor& log_alpha, const HardConcreteParams& p) {
  return (at::sigmoid(log_alpha) * (p.r - p.l) + p.l).clamp(0, 1);
}

double dropProbability(double p_base, double confidence, double log_alpha, bool use_confidence,
                       bool use_structure, const HardConcreteParams& p) {
  const double semantic = use_confidence ? 1.0 - std::clamp(confidence, 0.0, 1.0) : 1.0;
  const double learned = use_structure ? 1.0 - probabilityNonZero(log_alpha, p) : 1.0;
  return std::clamp(p_base * semantic * learned, 0.0, 1.0);
}

}  // namespace semantic_drop
}  // namespace sadsplat
