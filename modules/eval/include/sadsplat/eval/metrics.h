#pragma once
/// \file metrics.h
/// \brief Semantic segmentation metrics from a confusion matrix, ignoring label 255.

#include <cstdint>
#include <vector>

namespace sadsplat {
namespace eval {

/// \brief Counts[gt][pred] over pixels whose ground truth is a class (not 255).
class ConfusionMatrix {
 public:
  explicit ConfusionMatrix(int num_classes);
  /// \brief Adds pixels; gt == 255 (or any value >= num_classes) is ignored; pred must be a class.
  void add(const std::uint8_t* gt, const std::int64_t* pred, std::size_t n);
  /// \brief Adds another matrix's counts (the same number of classes).
  void add(const ConfusionMatrix& other);
  std::int64_t at(int gt, int pred) const {
    return counts_[static_cast<std::size_t>(gt) * n_ + pred];
  }
  int numClasses() const { return n_; }
  std::int64_t total() const;

  /// \brief IoU per class: TP / (TP + FP + FN); -1 for a class absent from both gt and prediction.
  std::vector<double> perClassIou() const;
  /// \brief Mean IoU over classes that occur in gt or prediction.
  double meanIou() const;
  /// \brief Mean over classes present in gt of TP / (TP + FN).
  double meanAccuracy() const;
  /// \brief Correct pixels / all counted pixels.
  double overallAccuracy() const;

 private:
  int n_;
  std::vector<std::int64_t> counts_;
};

/// \brief The confusion matrix of a class map ([height x width] row-major, cells `cell` wide)
/// over the cells whose centre lies within `radius` of the grid's centre: `truth` values >=
/// num_classes and cells where `covered` is 0 are left out; `predicted` must be a class where
/// covered. For an orbit capture the centre is what the photos look at.
/// \throws sadsplat::Error when the sizes disagree or a covered prediction is not a class
ConfusionMatrix confusionWithin(const std::vector<std::uint8_t>& truth,
                                const std::vector<std::uint8_t>& predicted,
                                const std::vector<std::uint8_t>& covered, int width, int height,
                                double cell, double radius, int num_classes);

}  // namespace eval
}  // namespace sadsplat
