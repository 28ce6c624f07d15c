#pragma once
/// \file class_extraction.h
/// \brief ClassExtraction: keeps the points of one class, as a PCL filter.

#include <pcl/filters/filter_indices.h>

#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/common/class_info.h"
#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace filters {

/// \brief Keeps the points whose `label` field equals a class id (setNegative: all others).
///
/// Works on any point type with a `label` field (GaussianPoint, pcl::PointXYZRGBL, ...), with
/// the vocabulary of pcl::FilterIndices: setInputCloud, setIndices, filter (cloud or indices),
/// setNegative, setKeepOrganized, getRemovedIndices (construct with `true`).
template <typename PointT>
class ClassExtraction : public pcl::FilterIndices<PointT> {
 public:
  using Ptr = std::shared_ptr<ClassExtraction<PointT>>;
  using ConstPtr = std::shared_ptr<const ClassExtraction<PointT>>;

  /// \param[in] extract_removed_indices whether getRemovedIndices() is filled
  explicit ClassExtraction(bool extract_removed_indices = false)
      : pcl::FilterIndices<PointT>(extract_removed_indices) {
    this->filter_name_ = "ClassExtraction";
  }

  /// \brief Selects the class by id.
  void setClassId(std::uint32_t id) { class_id_ = id; }
  /// \brief Selects the class by name.
  /// \throws sadsplat::Error if no class in `classes` has that name
  void setClassName(const std::string& name, const std::vector<ClassInfo>& classes);
  /// \brief The selected class id.
  std::uint32_t getClassId() const { return class_id_; }

 protected:
  using pcl::FilterIndices<PointT>::input_;
  using pcl::FilterIndices<PointT>::indices_;
  using pcl::FilterIndices<PointT>::negative_;
  using pcl::FilterIndices<PointT>::extract_removed_indices_;
  using pcl::FilterIndices<PointT>::removed_indices_;

  void applyFilter(pcl::Indices& indices) override;

 private:
  std::uint32_t class_id_ = 0;
};

}  // namespace filters
}  // namespace sadsplat

#ifdef PCL_NO_PRECOMPILE
#include "sadsplat/filters/impl/class_extraction.hpp"
#endif
