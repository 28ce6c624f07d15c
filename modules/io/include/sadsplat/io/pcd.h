#pragma once
/// \file pcd.h
/// \brief PCD files (PCL's format) for Gaussian and plain semantic clouds, read and written by
/// sadsplat's own validating codec: no pcl_io needed, so every build (the GPU one too) has it.
///
/// Files are written as binary PCD v0.7 that PCL's `pcl::PCDReader` and its tools read. The
/// readers accept ascii, binary and binary_compressed files from any PCL program, check the
/// header and the data size against the bytes present before allocating, and match fields by
/// name (converting numeric types): a missing required field is an error, never a default.

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>
#include <vector>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief What a PCD file holds, judged by its fields.
enum class PcdContent {
  kGaussians,  ///< GaussianPoint fields (x y z f_dc opacity scale rot ...)
  kSemantic,   ///< a plain semantic cloud: x y z, rgb or rgba, label
  kOther       ///< anything else
};

/// \brief Reads the header of `path` and says what it holds.
/// \throws sadsplat::Error when the file is missing or its header is invalid
PcdContent pcdContent(const std::string& path);

/// \brief The field names of a PCD file, in order (array fields once, with their COUNT).
std::vector<std::string> pcdFieldNames(const std::string& path);

/// \brief Writes a Gaussian cloud as a binary PCD (atomically). Array fields are PCD fields
/// with COUNT > 1 (f_dc 3, f_rest 45, scale 3, rot 4, feature 32).
/// \throws sadsplat::Error naming the file when it cannot be written
void savePcd(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud);
/// \brief Writes a plain semantic cloud (x y z rgba label) as a binary PCD (atomically).
void savePcd(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud);

/// \brief Reads a PCD with GaussianPoint's fields (written by savePcd or any PCL program).
/// Required: x y z f_dc opacity scale rot; the others keep GaussianPoint's defaults when absent.
/// Every value must be finite.
/// \throws sadsplat::Error naming the file and field when it is missing, invalid or lacks a field
pcl::PointCloud<GaussianPoint> loadGaussianPcd(const std::string& path);

/// \brief Reads a plain semantic cloud: x y z, rgb or rgba, label (a label of -1 in a signed
/// field is read as kUnlabelled). NaN coordinates are kept (is_dense is then false).
/// \throws sadsplat::Error naming the file and field when it is missing, invalid or lacks a field
pcl::PointCloud<pcl::PointXYZRGBL> loadSemanticPcd(const std::string& path);

}  // namespace io
}  // namespace sadsplat
