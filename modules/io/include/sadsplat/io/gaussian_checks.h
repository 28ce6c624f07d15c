#pragma once
/// \file gaussian_checks.h
/// \brief The values every Gaussian file reader accepts and every writer produces, in one place,
/// so that sadsplat never writes a file it refuses to read back.
///
/// A value is checked after conversion to its stored type (float): a PLY `double` of 1e300 or
/// an ascii 1e39 is infinite as a float and refused, not silently read as +inf. Beyond finiteness
/// two ranges are refused as implausible (no real model has them; they come from corrupt files):
/// positions beyond +-kMaxAbsPosition and log-scales beyond +-kMaxAbsLogScale. An infinite
/// opacity logit (what 3DGS decoders make of an 8-bit alpha of 0 or 255) is clamped to
/// +-kMaxOpacityLogit and counted instead: it means "fully transparent / opaque".

#include <pcl/point_cloud.h>

#include <cstddef>
#include <string>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief Largest accepted |x|, |y|, |z| (metres in a georeferenced scene): 10,000 km.
constexpr float kMaxAbsPosition = 1e7f;
/// \brief Largest accepted |log-scale| (exp(50) = 5e21; the 3DGS range is about -15..5).
constexpr float kMaxAbsLogScale = 50.0f;
/// \brief An infinite opacity logit is clamped to this (sigmoid(16) = 1 - 1.1e-7).
constexpr float kMaxOpacityLogit = 16.0f;

/// \brief What checking a cloud that was read changed.
struct GaussianReadReport {
  std::size_t clamped_opacities = 0;  ///< infinite opacity logits clamped to +-kMaxOpacityLogit
};

/// \brief Checks the Gaussians read from `path` and clamps infinite opacities.
/// \throws sadsplat::Error naming the file, the Gaussian's index and the field on a NaN or an
/// infinite value (opacity excepted) or a position or log-scale outside the ranges above
GaussianReadReport checkReadGaussians(const std::string& path,
                                      pcl::PointCloud<GaussianPoint>& cloud);

/// \brief Checks a cloud before it is written to `path`: the same rules, without clamping.
/// \throws sadsplat::Error naming the output file, the Gaussian and the field
void checkWritableGaussians(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud);

}  // namespace io
}  // namespace sadsplat
