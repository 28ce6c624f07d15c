#pragma once
/// \file few_shot_classifier.h
/// \brief The built-in backend's scorer: multinomial logistic regression on standardised region
/// descriptors and their pairwise products, fitted on the regions of the few labelled views,
/// with a temperature chosen by leave-one-view-out likelihood so that the class probabilities
/// are calibrated on views the fit has not seen.

#include <cstdint>
#include <vector>

namespace sadsplat {
namespace pseudo_labels {

/// \brief Fit parameters.
struct ClassifierOptions {
  double l2 = 1e-3;  ///< weight decay on the weights (not the bias)
  int steps = 400;   ///< Adam steps of the full-batch fit
  double learning_rate = 0.05;
  /// Add pairwise products of the standardised descriptors, when there are at least
  /// `quadratic_min_samples_per_weight` samples per expanded dimension (otherwise the products
  /// overfit and the most confident predictions become those of outliers).
  bool quadratic = true;
  double quadratic_min_samples_per_weight = 10.0;
};

/// \brief A calibrated few-shot classifier of region descriptors.
class FewShotClassifier {
 public:
  explicit FewShotClassifier(ClassifierOptions options = {}) : options_(options) {}

  /// \brief Fits on `n` samples.
  /// \param[in] features n x dim descriptors (row-major)
  /// \param[in] labels n class ids in [0, num_classes)
  /// \param[in] groups n group ids (the view a sample comes from); with two or more groups the
  ///            temperature is fitted on held-out groups, otherwise it stays 1
  /// \throws sadsplat::Error on empty or inconsistent input
  void fit(const std::vector<float>& features, int dim, const std::vector<int>& labels,
           const std::vector<int>& groups, int num_classes);

  /// \brief Class probabilities, n x num_classes (rows sum to 1).
  std::vector<float> predictProbabilities(const std::vector<float>& features) const;

  double temperature() const { return temperature_; }
  /// \brief Whether the last fit used the pairwise products.
  bool usedQuadratic() const { return use_quadratic_; }
  int numClasses() const { return num_classes_; }

 private:
  struct Model {
    std::vector<float> weight;  // expanded_dim x num_classes
    std::vector<float> bias;    // num_classes
  };
  std::vector<float> expand(const std::vector<float>& features) const;
  Model fitModel(const std::vector<float>& expanded, const std::vector<int>& labels,
                 const std::vector<std::size_t>& rows) const;
  std::vector<float> logits(const Model& model, const std::vector<float>& expanded) const;

  ClassifierOptions options_;
  int dim_ = 0, expanded_dim_ = 0, num_classes_ = 0;
  std::vector<float> mean_, scale_;
  Model model_;
  double temperature_ = 1.0;
  bool use_quadratic_ = false;
};

}  // namespace pseudo_labels
}  // namespace sadsplat
