#include "sadsplat/pseudo_labels/target_filter.h"

#include <algorithm>
#include <cmath>

namespace sadsplat {
namespace pseudo_labels {

TargetMeasures measureTarget(const float* scores, int num_classes, ScoreScale scale) {
  TargetMeasures m;
  double top1 = 0, top2 = 0, sum = 0;
  for (int c = 0; c < num_classes; ++c) {
    const double s = std::max(0.0f, scores[c]);
    sum += s;
    if (s > top1) {
      top2 = top1;
      top1 = s;
      m.top_class = c;
    } else if (s > top2) {
      top2 = s;
    }
  }
  if (scale == ScoreScale::kLogOdds) {
    constexpr double e = 1e-6;
    const double p1 = std::clamp(top1 / std::max(sum, e), e, 1 - e),
                 p2 = std::clamp(top2 / std::max(sum, e), e, 1 - e);
    m.top1 = std::log(p1 / (1 - p1));
    m.delta_top = std::log(p1 / p2);
  } else {
    m.top1 = top1;
    m.delta_top = top1 - top2;
  }
  if (sum > 0) {
    for (int c = 0; c < num_classes; ++c) {
      const double p = std::max(0.0f, scores[c]) / sum;
      if (p > 0) m.entropy -= p * std::log(p);
    }
  } else {
    m.entropy = std::log(static_cast<double>(num_classes));  // no evidence: uniform
  }
  return m;
}

TargetStatistics targetStatistics(const std::vector<TargetMeasures>& targets) {
  TargetStatistics s;
  s.count = targets.size();
  if (targets.empty()) return s;
  const double n = static_cast<double>(targets.size());
  for (const auto& t : targets) {
    s.top1_mean += t.top1 / n;
    s.delta_top_mean += t.delta_top / n;
    s.entropy_mean += t.entropy / n;
  }
  for (const auto& t : targets) {
    s.top1_std += std::pow(t.top1 - s.top1_mean, 2) / n;
    s.delta_top_std += std::pow(t.delta_top - s.delta_top_mean, 2) / n;
    s.entropy_std += std::pow(t.entropy - s.entropy_mean, 2) / n;
  }
  s.top1_std = std::sqrt(s.top1_std);
  s.delta_top_std = std::sqrt(s.delta_top_std);
  s.entropy_std = std::sqrt(s.entropy_std);
  return s;
}

std::vector<TargetStatistics> classStatistics(const std::vector<TargetMeasures>& targets,
                                              int num_classes, std::size_t min_targets) {
  std::vector<std::vector<TargetMeasures>> by_class(num_classes);
  for (const TargetMeasures& t : targets) {
    if (t.top_class >= 0 && t.top_class < num_classes) by_class[t.top_class].push_back(t);
  }
  const TargetStatistics all = targetStatistics(targets);
  std::vector<TargetStatistics> out;
  for (const auto& members : by_class) {
    out.push_back(members.size() >= min_targets ? targetStatistics(members) : all);
  }
  return out;
}

bool keepTarget(const TargetMeasures& t, const TargetStatistics& s, double k) {
  return t.top1 > s.top1_mean + k * s.top1_std &&
         t.delta_top > s.delta_top_mean + k * s.delta_top_std &&
         t.entropy < s.entropy_mean + k * s.entropy_std;
}

}  // namespace pseudo_labels
}  // namespace sadsplat
