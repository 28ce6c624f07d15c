#pragma once
/// \file gaussian_ply.h
/// \brief The 3D Gaussian Splatting PLY file, with sadsplat's semantic properties, without pcl_io.
///
/// Written layout (binary little endian, one `vertex` element, float32 unless noted):
/// `x y z nx ny nz f_dc_0..2 f_rest_0..(3K-1) opacity scale_0..2 rot_0..3` — the standard 3DGS
/// layout, K = (degree+1)^2 - 1 rest coefficients per channel, channel-major — followed, when
/// semantic properties are written, by `feature_0..31 log_alpha confidence` and `uint label`.
/// Splat viewers ignore the extra properties.

#include <pcl/point_cloud.h>

#include <string>
#include <vector>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief What writeGaussianPly writes.
struct PlyWriteOptions {
  int sh_degree = kMaxShDegree;  ///< 0..3; higher coefficients of the points are not written
  bool semantic = true;          ///< write feature_*, log_alpha, confidence, label
  int feature_dim = kFeatureDim;  ///< 0..kFeatureDim feature_* properties when semantic
};

/// \brief What readGaussianPly found in a file.
struct PlyFileInfo {
  std::string format;  ///< "ascii", "binary_little_endian", ...
  std::size_t num_vertices = 0;
  int sh_degree = 0;  ///< from the number of f_rest_* properties
  bool has_normals = false;
  bool has_semantic = false;                    ///< any feature_*/log_alpha/confidence/label
  int feature_dim = 0;                          ///< number of feature_* properties
  std::vector<std::string> ignored_properties;  ///< vertex properties sadsplat does not know
  std::size_t clamped_opacities = 0;  ///< infinite opacities clamped (gaussian_checks.h)
};

/// \brief Writes a cloud as a binary little-endian 3DGS PLY (atomically).
/// \throws sadsplat::Error on bad options or a write failure
void writeGaussianPly(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
                      const PlyWriteOptions& options = {});

/// \brief Reads a 3DGS PLY (ascii or binary, either endianness, any SH degree 0..3, with or
/// without normals and semantic properties; unknown properties and elements are skipped).
///
/// Properties a file lacks take GaussianPoint's defaults. Required: x y z f_dc_0..2 opacity
/// scale_0..2 rot_0..3. Every value must be finite as a float and plausible (gaussian_checks.h);
/// an infinite opacity is clamped and counted. Elements after the vertices must be complete.
/// \param[in] path the file
/// \param[out] info if not null, what the file contained
/// \throws sadsplat::Error naming the file, the element/property/vertex and the expectation
pcl::PointCloud<GaussianPoint> readGaussianPly(const std::string& path,
                                               PlyFileInfo* info = nullptr);

}  // namespace io
}  // namespace sadsplat
