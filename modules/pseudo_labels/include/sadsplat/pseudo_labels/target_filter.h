#pragma once
/// \file target_filter.h
/// \brief The paper's high-confidence filter ("Pseudo-Label Generation Module"): per target the
/// TOP1 score, dTOP = TOP1 - TOP2 and the entropy of its class distribution; with mean and
/// standard deviation of each over all targets of the training set, a target is kept only if
/// TOP1 > mean + k std, dTOP > mean + k std and entropy < mean + k std (the paper: k = 1).

#include <vector>

namespace sadsplat {
namespace pseudo_labels {

/// \brief The three measures of one target.
struct TargetMeasures {
  double top1 = 0;
  double delta_top = 0;  ///< TOP1 - TOP2
  double entropy = 0;    ///< natural log, of the scores normalised to sum 1
  int top_class = -1;    ///< the class of TOP1 (-1: no positive score)
};

/// \brief Mean and (population) standard deviation of each measure over a set of targets.
struct TargetStatistics {
  double top1_mean = 0, top1_std = 0;
  double delta_top_mean = 0, delta_top_std = 0;
  double entropy_mean = 0, entropy_std = 0;
  std::size_t count = 0;
};

/// \brief The scale on which TOP1 and dTOP are measured.
enum class ScoreScale {
  kScore,   ///< the scores themselves (the paper, whose scores are CLIP cosine similarities)
  kLogOdds  ///< TOP1 as log(p1 / (1 - p1)), dTOP as log(p1 / p2): for probabilities, whose TOP1
            ///< piles up below 1 so that mean + std of the raw values exceeds 1
};

/// \brief Measures of a target from its `num_classes` non-negative scores.
TargetMeasures measureTarget(const float* scores, int num_classes,
                             ScoreScale scale = ScoreScale::kScore);

/// \brief Statistics over the targets.
TargetStatistics targetStatistics(const std::vector<TargetMeasures>& targets);

/// \brief Statistics of the targets of each TOP1 class (class-balanced filtering), indexed by
/// class; a class with fewer than `min_targets` targets gets the statistics over all targets.
std::vector<TargetStatistics> classStatistics(const std::vector<TargetMeasures>& targets,
                                              int num_classes, std::size_t min_targets = 10);

/// \brief The keep rule with thresholds mean + k std.
bool keepTarget(const TargetMeasures& target, const TargetStatistics& stats, double k = 1.0);

}  // namespace pseudo_labels
}  // namespace sadsplat
