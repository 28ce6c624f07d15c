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

}  // namespace eval
}  // namespace sadsplat
