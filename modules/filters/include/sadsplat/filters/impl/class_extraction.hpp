#pragma once
// Template implementation of ClassExtraction; instantiated in class_extraction.cpp for
// GaussianPoint and pcl::PointXYZRGBL, included by users who define PCL_NO_PRECOMPILE.

#include "sadsplat/common/error.h"
#include "sadsplat/filters/class_extraction.h"

namespace sadsplat {
namespace filters {

template <typename PointT>
void ClassExtraction<PointT>::setClassName(const std::string& name,
                                           const std::vector<ClassInfo>& classes) {
  const auto id = findClass(classes, name);
  if (!id) {
    std::string known;
    for (const auto& c : classes) known += (known.empty() ? "" : ", ") + c.name;
    throw Error("<classes>", "class name", "one of: " + known, name);
  }
  class_id_ = *id;
}

template <typename PointT>
void ClassExtraction<PointT>::applyFilter(pcl::Indices& indices) {
  indices.clear();
  indices.reserve(indices_->size());
  if (extract_removed_indices_) removed_indices_->clear();
  for (const auto index : *indices_) {
    const bool in_class = (*input_)[index].label == class_id_;
    if (in_class != negative_) {
      indices.push_back(index);
    } else if (extract_removed_indices_) {
      removed_indices_->push_back(index);
    }
  }
}

}  // namespace filters
}  // namespace sadsplat
