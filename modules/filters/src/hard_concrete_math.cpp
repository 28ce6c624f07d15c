#include "sadsplat/filters/hard_concrete_math.h"

#include <algorithm>
#include <cmath>

namespace sadsplat {
namespace filters {

double logitOfThreshold(const HardConcreteParams& p) {
  const double t = -p.l / (p.r - p.l);
  return std::log(t / (1 - t));
}

double probabilityNonZero(double log_alpha, const HardConcreteParams& p) {
  return 1.0 / (1.0 + std::exp(-(log_alpha - p.beta * logitOfThreshold(p))));
}

double dropProbability(double p_base, double confidence, double log_alpha, bool use_confidence,
                       bool use_structure, const HardConcreteParams& p) {
  const double semantic = use_confidence ? 1.0 - std::clamp(confidence, 0.0, 1.0) : 1.0;
  const double learned = use_structure ? 1.0 - probabilityNonZero(log_alpha, p) : 1.0;
  return std::clamp(p_base * semantic * learned, 0.0, 1.0);
}

}  // namespace filters
}  // namespace sadsplat
