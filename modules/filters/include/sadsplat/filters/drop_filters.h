#pragma once
/// \file drop_filters.h
/// \brief The paper's drops as PCL filters, usable on a trained model after the fact:
/// HardConcreteDrop (structure only), ConfidenceDrop (semantic only), SemanticDrop (both).
///
/// Each point is removed with probability P_drop (hard_concrete_math.h) computed from its
/// `log_alpha` and `confidence` fields; the random draws come from `setSeed`, so the same seed
/// and input give the same result. setNegative(true) returns the points that would be removed;
/// getRemovedIndices() (construct with `true`) lists the complement of the output exactly.

#include <pcl/filters/filter_indices.h>

#include <cstdint>

#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/filters/hard_concrete_math.h"

namespace sadsplat {
namespace filters {

/// \brief Base of the drop filters: seeded Bernoulli removal with a per-point probability.
template <typename PointT>
class DropFilter : public pcl::FilterIndices<PointT> {
 public:
  using Ptr = std::shared_ptr<DropFilter<PointT>>;
  explicit DropFilter(bool extract_removed_indices = false)
      : pcl::FilterIndices<PointT>(extract_removed_indices) {}

  /// \brief Scale of the drop rate (paper: P_base, default 1).
  void setBaseRate(double p_base) { p_base_ = p_base; }
  double getBaseRate() const { return p_base_; }
  /// \brief Seed of the random draws.
  void setSeed(std::uint64_t seed) { seed_ = seed; }
  std::uint64_t getSeed() const { return seed_; }
  /// \brief Hard Concrete parameters used for P_learned.
  void setHardConcreteParams(const HardConcreteParams& p) { hc_ = p; }

  /// \brief The drop probability of one point.
  virtual double dropProbability(const PointT& point) const = 0;

 protected:
  using pcl::FilterIndices<PointT>::input_;
  using pcl::FilterIndices<PointT>::indices_;
  using pcl::FilterIndices<PointT>::negative_;
  using pcl::FilterIndices<PointT>::extract_removed_indices_;
  using pcl::FilterIndices<PointT>::removed_indices_;

  void applyFilter(pcl::Indices& indices) override;

  double p_base_ = 1.0;
  std::uint64_t seed_ = 42;
  HardConcreteParams hc_;
};

/// \brief Structure-only drop: P_drop = clamp(P_base (1 - P_nonzero(log_alpha)), 0, 1).
template <typename PointT>
class HardConcreteDrop : public DropFilter<PointT> {
 public:
  using Ptr = std::shared_ptr<HardConcreteDrop<PointT>>;
  explicit HardConcreteDrop(bool extract_removed_indices = false)
      : DropFilter<PointT>(extract_removed_indices) {
    this->filter_name_ = "HardConcreteDrop";
  }
  double dropProbability(const PointT& p) const override {
    return filters::dropProbability(this->p_base_, 0.0, p.log_alpha, false, true, this->hc_);
  }
};

/// \brief Semantic-only drop: P_drop = clamp(P_base (1 - confidence), 0, 1).
template <typename PointT>
class ConfidenceDrop : public DropFilter<PointT> {
 public:
  using Ptr = std::shared_ptr<ConfidenceDrop<PointT>>;
  explicit ConfidenceDrop(bool extract_removed_indices = false)
      : DropFilter<PointT>(extract_removed_indices) {
    this->filter_name_ = "ConfidenceDrop";
  }
  double dropProbability(const PointT& p) const override {
    return filters::dropProbability(this->p_base_, p.confidence, 0.0, true, false, this->hc_);
  }
};

/// \brief The combined rule of the paper: P_drop = clamp(P_base (1 - P_conf) P_learned, 0, 1).
template <typename PointT>
class SemanticDrop : public DropFilter<PointT> {
 public:
  using Ptr = std::shared_ptr<SemanticDrop<PointT>>;
  explicit SemanticDrop(bool extract_removed_indices = false)
      : DropFilter<PointT>(extract_removed_indices) {
    this->filter_name_ = "SemanticDrop";
  }
  double dropProbability(const PointT& p) const override {
    return filters::dropProbability(this->p_base_, p.confidence, p.log_alpha, true, true,
                                          this->hc_);
  }
};

}  // namespace filters
}  // namespace sadsplat

#ifdef PCL_NO_PRECOMPILE
#include "sadsplat/filters/impl/drop_filters.hpp"
#endif
