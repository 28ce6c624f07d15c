#include "sadsplat/pseudo_labels/few_shot_classifier.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace pseudo_labels {
namespace {

at::Tensor fromVector(const std::vector<float>& v, std::int64_t rows, std::int64_t cols) {
  return at::from_blob(const_cast<float*>(v.data()), {rows, cols}, at::kFloat).clone();
}
std::vector<float> toVector(const at::Tensor& t) {
  const at::Tensor c = t.contiguous().to(at::kFloat);
  return std::vector<float>(c.data_ptr<float>(), c.data_ptr<float>() + c.numel());
}

}  // namespace

std::vector<float> FewShotClassifier::expand(const std::vector<float>& features) const {
  const std::size_t n = features.size() / dim_;
  std::vector<float> out(n * expanded_dim_);
  std::vector<float> z(dim_);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < dim_; ++k) z[k] = (features[i * dim_ + k] - mean_[k]) / scale_[k];
    float* o = &out[i * expanded_dim_];
    int m = 0;
    for (int k = 0; k < dim_; ++k) o[m++] = z[k];
    if (use_quadratic_) {
      for (int a = 0; a < dim_; ++a) {
        for (int b = a; b < dim_; ++b) o[m++] = z[a] * z[b] / std::sqrt(2.0f);
      }
    }
  }
  return out;
}

FewShotClassifier::Model FewShotClassifier::fitModel(const std::vector<float>& expanded,
                                                     const std::vector<int>& labels,
                                                     const std::vector<std::size_t>& rows) const {
  const std::int64_t n = static_cast<std::int64_t>(rows.size()), D = expanded_dim_,
                     C = num_classes_;
  at::Tensor X = at::empty({n, D}, at::kFloat), Y = at::zeros({n, C}, at::kFloat);
  float* xp = X.data_ptr<float>();
  float* yp = Y.data_ptr<float>();
  for (std::int64_t i = 0; i < n; ++i) {
    std::copy_n(&expanded[rows[i] * D], D, xp + i * D);
    yp[i * C + labels[rows[i]]] = 1.0f;
  }
  at::Tensor W = at::zeros({D, C}, at::kFloat), b = at::zeros({C}, at::kFloat);
  // Start the bias at the log class frequencies (faster, and exact for an uninformative X).
  b = at::log(Y.mean(0) + 1e-3);
  at::Tensor mW = at::zeros_like(W), vW = at::zeros_like(W), mb = at::zeros_like(b),
             vb = at::zeros_like(b);
  const double b1 = 0.9, b2 = 0.999, eps = 1e-8, lr = options_.learning_rate;
  for (int step = 1; step <= options_.steps; ++step) {
    const at::Tensor P = at::softmax(at::matmul(X, W) + b, 1);
    const at::Tensor dZ = (P - Y) / static_cast<double>(n);
    const at::Tensor gW = at::matmul(X.t(), dZ) + options_.l2 * W;
    const at::Tensor gb = dZ.sum(0);
    const double c1 = 1 - std::pow(b1, step), c2 = 1 - std::pow(b2, step);
    mW.mul_(b1).add_(gW, 1 - b1);
    vW.mul_(b2).addcmul_(gW, gW, 1 - b2);
    mb.mul_(b1).add_(gb, 1 - b1);
    vb.mul_(b2).addcmul_(gb, gb, 1 - b2);
    W.sub_(lr * (mW / c1) / ((vW / c2).sqrt() + eps));
    b.sub_(lr * (mb / c1) / ((vb / c2).sqrt() + eps));
  }
  return {toVector(W), toVector(b)};
}

std::vector<float> FewShotClassifier::logits(const Model& model,
                                             const std::vector<float>& expanded) const {
  const std::int64_t n = static_cast<std::int64_t>(expanded.size() / expanded_dim_);
  const at::Tensor Z = at::matmul(fromVector(expanded, n, expanded_dim_),
                                  fromVector(model.weight, expanded_dim_, num_classes_)) +
                       fromVector(model.bias, 1, num_classes_);
  return toVector(Z);
}

void FewShotClassifier::fit(const std::vector<float>& features, int dim,
                            const std::vector<int>& labels, const std::vector<int>& groups,
                            int num_classes) {
  if (dim < 1 || num_classes < 2 || labels.empty() || features.size() != labels.size() * dim ||
      groups.size() != labels.size()) {
    throw Error("<few-shot classifier>", "training samples",
                "n x dim descriptors with n labels and n groups, at least 2 classes",
                std::to_string(labels.size()) + " labels, " + std::to_string(features.size()) +
                    " values, " + std::to_string(num_classes) + " classes");
  }
  for (int l : labels) {
    if (l < 0 || l >= num_classes) {
      throw Error("<few-shot classifier>", "label", "0.." + std::to_string(num_classes - 1),
                  std::to_string(l));
    }
  }
  dim_ = dim;
  num_classes_ = num_classes;
  const std::size_t n = labels.size();
  const int quadratic_dim = dim + dim * (dim + 1) / 2;
  use_quadratic_ =
      options_.quadratic && n >= options_.quadratic_min_samples_per_weight * quadratic_dim;
  expanded_dim_ = use_quadratic_ ? quadratic_dim : dim;
  mean_.assign(dim, 0.0f);
  scale_.assign(dim, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < dim; ++k) mean_[k] += features[i * dim + k] / n;
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < dim; ++k) scale_[k] += std::pow(features[i * dim + k] - mean_[k], 2.0f) / n;
  }
  for (float& s : scale_) s = std::max(1e-6f, std::sqrt(s));
  const std::vector<float> expanded = expand(features);

  // Temperature: out-of-group logits from fits that did not see the group, then the T that
  // maximises their likelihood (a grid; the likelihood is smooth and unimodal in T).
  temperature_ = 1.0;
  const std::set<int> distinct(groups.begin(), groups.end());
  if (distinct.size() >= 2) {
    std::vector<float> held_out_logits(n * num_classes);
    for (int g : distinct) {
      std::vector<std::size_t> train_rows, test_rows;
      for (std::size_t i = 0; i < n; ++i) (groups[i] == g ? test_rows : train_rows).push_back(i);
      const Model m = fitModel(expanded, labels, train_rows);
      std::vector<float> test_x(test_rows.size() * expanded_dim_);
      for (std::size_t j = 0; j < test_rows.size(); ++j) {
        std::copy_n(&expanded[test_rows[j] * expanded_dim_], expanded_dim_,
                    &test_x[j * expanded_dim_]);
      }
      const std::vector<float> z = logits(m, test_x);
      for (std::size_t j = 0; j < test_rows.size(); ++j) {
        std::copy_n(&z[j * num_classes], num_classes, &held_out_logits[test_rows[j] * num_classes]);
      }
    }
    const at::Tensor Z = fromVector(held_out_logits, static_cast<std::int64_t>(n), num_classes);
    at::Tensor target = at::empty({static_cast<std::int64_t>(n)}, at::kLong);
    for (std::size_t i = 0; i < n; ++i) target[i] = labels[i];
    double best = 1e300;
    for (double T = 0.25; T <= 8.0 + 1e-9; T *= 1.05) {
      const double nll =
          -at::log_softmax(Z / T, 1).gather(1, target.unsqueeze(1)).mean().item<double>();
      if (nll < best) best = nll, temperature_ = T;
    }
  }
  std::vector<std::size_t> all(n);
  for (std::size_t i = 0; i < n; ++i) all[i] = i;
  model_ = fitModel(expanded, labels, all);
}

std::vector<float> FewShotClassifier::predictProbabilities(
    const std::vector<float>& features) const {
  if (dim_ == 0)
    throw Error("<few-shot classifier>", "state", "fit() before predicting", "predict before fit");
  if (features.size() % dim_ != 0)
    throw Error("<few-shot classifier>", "features", "n x dim values",
                std::to_string(features.size()) + " values for dim " + std::to_string(dim_));
  if (features.empty()) return {};
  const std::vector<float> z = logits(model_, expand(features));
  const std::int64_t n = static_cast<std::int64_t>(features.size() / dim_);
  return toVector(at::softmax(fromVector(z, n, num_classes_) / temperature_, 1));
}

}  // namespace pseudo_labels
}  // namespace sadsplat
