#include "sadsplat/eval/metrics.h"

#include <algorithm>
#include <string>

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

ConfusionMatrix confusionWithin(const std::vector<std::uint8_t>& truth,
                                const std::vector<std::uint8_t>& predicted,
                                const std::vector<std::uint8_t>& covered, int width, int height,
                                double cell, double radius, int num_classes) {
  const std::size_t n = static_cast<std::size_t>(std::max(0, width)) * std::max(0, height);
  if (truth.size() != n || predicted.size() != n || covered.size() != n) {
    throw Error("<class map scores>", "grid",
                "truth, prediction and cover of " + std::to_string(n) + " cells each",
                std::to_string(truth.size()) + ", " + std::to_string(predicted.size()) + ", " +
                    std::to_string(covered.size()));
  }
  ConfusionMatrix m(num_classes);
  for (int y = 0; y < height; ++y) {
    const double dy = (y + 0.5 - 0.5 * height) * cell;
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      if (truth[i] >= num_classes || !covered[i]) continue;
      const double dx = (x + 0.5 - 0.5 * width) * cell;
      if (dx * dx + dy * dy > radius * radius) continue;
      if (predicted[i] >= num_classes) {
        throw Error("<class map scores>", "prediction",
                    "a class below " + std::to_string(num_classes) + " where covered",
                    std::to_string(predicted[i]));
      }
      const std::int64_t p = predicted[i];
      m.add(&truth[i], &p, 1);
    }
  }
  return m;
}

}  // namespace eval
}  // namespace sadsplat
