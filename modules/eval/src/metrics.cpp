#include "sadsplat/eval/metrics.h"

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace eval {

ConfusionMatrix::ConfusionMatrix(int num_classes)
    : n_(num_classes), counts_(static_cast<std::size_t>(num_classes) * num_classes, 0) {}

void ConfusionMatrix::add(const std::uint8_t* gt, const std::int64_t* pred, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (gt[i] >= n_) continue;
    if (pred[i] < 0 || pred[i] >= n_) {
      throw Error("<evaluation>", "prediction", "a class id below " + std::to_string(n_),
                  std::to_string(pred[i]));
    }
    ++counts_[static_cast<std::size_t>(gt[i]) * n_ + pred[i]];
  }
}

void ConfusionMatrix::add(const ConfusionMatrix& other) {
  if (other.n_ != n_) {
    throw Error("<evaluation>", "confusion matrix", std::to_string(n_) + " classes",
                std::to_string(other.n_));
  }
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
}

std::int64_t ConfusionMatrix::total() const {
  std::int64_t t = 0;
  for (auto c : counts_) t += c;
  return t;
}

std::vector<double> ConfusionMatrix::perClassIou() const {
  std::vector<double> iou(n_, -1.0);
  for (int c = 0; c < n_; ++c) {
    std::int64_t tp = at(c, c), fp = 0, fn = 0;
    for (int k = 0; k < n_; ++k) {
      if (k == c) continue;
      fp += at(k, c);
      fn += at(c, k);
    }
    if (tp + fp + fn > 0) iou[c] = static_cast<double>(tp) / static_cast<double>(tp + fp + fn);
  }
  return iou;
}

double ConfusionMatrix::meanIou() const {
  double sum = 0;
  int count = 0;
  for (double v : perClassIou()) {
    if (v >= 0) {
      sum += v;
      ++count;
    }
  }
  return count ? sum / count : 0.0;
}

double ConfusionMatrix::meanAccuracy() const {
  double sum = 0;
  int count = 0;
  for (int c = 0; c < n_; ++c) {
    std::int64_t row = 0;
    for (int k = 0; k < n_; ++k) row += at(c, k);
    if (row > 0) {
      sum += static_cast<double>(at(c, c)) / static_cast<double>(row);
      ++count;
    }
  }
  return count ? sum / count : 0.0;
}

double ConfusionMatrix::overallAccuracy() const {
  std::int64_t correct = 0;
  for (int c = 0; c < n_; ++c) correct += at(c, c);
  const std::int64_t t = total();
  return t ? static_cast<double>(correct) / static_cast<double>(t) : 0.0;
}

}  // namespace eval
}  // namespace sadsplat
