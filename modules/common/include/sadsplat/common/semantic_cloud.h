#pragma once
/// \file semantic_cloud.h
/// \brief Plain semantic point clouds (pcl::PointXYZRGBL) for downstream PCL pipelines.

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vector>

#include "sadsplat/common/class_info.h"
#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {

/// \brief Colour given to points whose label is kUnlabelled.
constexpr std::uint8_t kUnlabelledGrey = 128;

/// \brief Gaussian centres as a pcl::PointXYZRGBL cloud: colour = class colour, label = class id.
///
/// Unlabelled Gaussians keep label kUnlabelled and are grey. The header, width, height and
/// is_dense of the input are kept.
/// \param[in] cloud trained Gaussians
/// \param[in] classes the scene's classes; every label must be an index into it or kUnlabelled
/// \throws sadsplat::Error if a label is neither
pcl::PointCloud<pcl::PointXYZRGBL> toSemanticCloud(const pcl::PointCloud<GaussianPoint>& cloud,
                                                   const std::vector<ClassInfo>& classes);

}  // namespace sadsplat
