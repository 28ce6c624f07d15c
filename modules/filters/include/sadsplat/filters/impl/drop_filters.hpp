#pragma once
// Template implementation of the drop filters; instantiated for GaussianPoint in
// drop_filters.cpp, included by users who define PCL_NO_PRECOMPILE.

#include <random>

#include "sadsplat/filters/drop_filters.h"

namespace sadsplat {
namespace filters {

template <typename PointT>
void DropFilter<PointT>::applyFilter(pcl::Indices& indices) {
  indices.clear();
  indices.reserve(indices_->size());
  if (extract_removed_indices_) removed_indices_->clear();
  std::mt19937_64 rng(seed_);
  for (const auto index : *indices_) {
    // 53-bit uniform in [0, 1) from the raw engine: the same on every standard library.
    const double u = static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
    const bool dropped = u < dropProbability((*input_)[index]);
    if (dropped == negative_) {
      indices.push_back(index);
    } else if (extract_removed_indices_) {
      removed_indices_->push_back(index);
    }
  }
}

}  // namespace filters
}  // namespace sadsplat
