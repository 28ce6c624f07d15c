#pragma once
/// \file pcd.h
/// \brief PCD files through PCL's pcl_io, for Gaussian and plain semantic clouds.
/// Available when sadsplat is built with pcl_io (SADSPLAT_WITH_VTK=ON, SADSPLAT_HAVE_PCL_IO).

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief Whether this build can read and write PCD files.
bool havePcdSupport();

/// \brief Writes a Gaussian cloud as a binary PCD (atomically). Array fields are PCD fields
/// with COUNT > 1 (f_dc 3, f_rest 45, scale 3, rot 4, feature 32).
/// \throws sadsplat::Error on failure or when the build has no pcl_io
void savePcd(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud);
/// \brief Writes a plain semantic cloud (x y z rgb label) as a binary PCD (atomically).
void savePcd(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud);

/// \brief Reads a PCD written by savePcd (or any PCD with GaussianPoint's fields).
/// \throws sadsplat::Error naming the file when it is missing, unreadable or lacks a field
pcl::PointCloud<GaussianPoint> loadGaussianPcd(const std::string& path);

}  // namespace io
}  // namespace sadsplat
