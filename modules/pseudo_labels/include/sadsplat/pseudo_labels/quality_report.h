#pragma once
/// \file quality_report.h
/// \brief Quality of pseudo-labels against ground truth, on the training views that have label
/// maps but do not supervise training (the views pseudo-labels are for): precision of the kept
/// pseudo-labels, coverage (share of labelled pixels that received a pseudo-label), both per
/// class, and the reliability of the confidence (accuracy of the argmax per TOP1 bin, over all
/// targets, kept or not).

#include <string>
#include <vector>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pseudo_labels {

/// \brief Accuracy of the argmax class over the pixels whose TOP1 score lies in a bin.
struct ReliabilityBin {
  double low = 0, high = 0;
  std::size_t pixels = 0;
  double accuracy = 0;    ///< share of those pixels whose argmax is the ground truth
  double mean_score = 0;  ///< mean TOP1 score of those pixels
};

/// \brief Precision and coverage of one class.
struct ClassQuality {
  std::string name;
  std::size_t gt_pixels = 0;         ///< ground-truth pixels of the class
  std::size_t predicted_pixels = 0;  ///< kept pixels pseudo-labelled with the class
  double precision = 0;              ///< of the pixels pseudo-labelled with the class
  double coverage = 0;               ///< share of the class's ground-truth pixels kept
};

/// \brief The whole report.
struct PseudoLabelQuality {
  int views = 0;                ///< views evaluated
  std::size_t gt_pixels = 0;    ///< pixels with a ground-truth class
  std::size_t kept_pixels = 0;  ///< of those, pixels with a kept pseudo-label
  double precision = 0;         ///< kept pixels whose pseudo-label is right
  double coverage = 0;          ///< kept_pixels / gt_pixels
  double argmax_accuracy = 0;   ///< argmax of the scores over all target pixels (no filter)
  double expected_calibration_error = 0;
  std::vector<ClassQuality> classes;
  /// The least precise class among those pseudo-labelling at least kWorstClassMinShare of the
  /// labelled pixels (a class with a handful of wrong pixels does not count); -1 if none. Pooled
  /// precision hides a class that is mostly wrong; training suffers from exactly that one.
  int worst_class = -1;
  static constexpr double kWorstClassMinShare = 0.0005;
  std::vector<ReliabilityBin> reliability;

  std::string toJson() const;
  std::string toText() const;
};

/// \brief Evaluates the pseudo-labels of `scene` (10 reliability bins).
/// \throws sadsplat::Error if no view has both pseudo-labels and unused ground truth
PseudoLabelQuality evaluatePseudoLabels(const io::Scene& scene);

}  // namespace pseudo_labels
}  // namespace sadsplat
