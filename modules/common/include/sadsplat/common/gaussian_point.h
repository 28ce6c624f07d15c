#pragma once
/// \file gaussian_point.h
/// \brief sadsplat::GaussianPoint, a semantic 3D Gaussian as a registered PCL point type.
///
/// The field names are the property names of the standard 3D Gaussian Splatting PLY (array
/// fields expand to `name_0`, `name_1`, ...), followed by sadsplat's semantic fields, so PLY,
/// PCD and PCL algorithms all see the same names:
///
/// | field        | count | meaning                                                        |
/// |--------------|-------|----------------------------------------------------------------|
/// | x y z        | 1 each| centre (world frame)                                           |
/// | nx ny nz     | 1 each| unused by 3DGS (kept for files that set them)                  |
/// | f_dc         | 3     | SH degree-0 coefficient per colour channel (R, G, B)           |
/// | f_rest       | 45    | SH degrees 1..3, channel-major: f_rest[c * 15 + k], k = 0..14  |
/// | opacity      | 1     | opacity logit (opacity = sigmoid(opacity))                     |
/// | scale        | 3     | log standard deviations along the local axes                   |
/// | rot          | 4     | rotation quaternion (w, x, y, z), not necessarily normalised   |
/// | feature      | 32    | semantic feature (Feature-3DGS style)                          |
/// | log_alpha    | 1     | Hard Concrete gate parameter (paper, "Learnable Structure Drop")|
/// | confidence   | 1     | semantic confidence in [0, 1] (paper, "Semantic Confidence Drop")|
/// | label        | 1     | class id, or kUnlabelled                                       |
///
/// The PCL algorithms below are explicitly instantiated for this type in sadsplat_common, in
/// the way PCL itself does for its own types; include their ordinary PCL headers and link
/// sadsplat::common: pcl::KdTreeFLANN, pcl::search::KdTree, pcl::VoxelGrid, pcl::ExtractIndices,
/// pcl::RandomSample, pcl::CropBox.
///
/// Note on pcl::VoxelGrid: PCL's centroid accumulator knows only its standard fields, so a
/// voxel's output point has the averaged centre and GaussianPoint's default values in every
/// other field. Use it for spatial subsampling of centres, not for merging Gaussians.

#include <cstdint>
#include <limits>

#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include "sadsplat/common/sh_degree.h"

namespace sadsplat {

/// \brief Number of spherical-harmonics coefficients beyond degree 0, per channel, at degree 3.
constexpr int kShRestPerChannel = 15;
/// \brief Highest spherical-harmonics degree a GaussianPoint stores.
constexpr int kMaxShDegree = 3;
/// \brief Length of the semantic feature a GaussianPoint stores.
constexpr int kFeatureDim = 32;
/// \brief `label` value of a Gaussian with no class.
constexpr std::uint32_t kUnlabelled = std::numeric_limits<std::uint32_t>::max();

/// \brief One semantic 3D Gaussian (see the file comment for the fields).
struct EIGEN_ALIGN16 GaussianPoint {
  PCL_ADD_POINT4D;  // x, y, z (+ padding)
  float nx;
  float ny;
  float nz;
  float f_dc[3];
  float f_rest[3 * kShRestPerChannel];
  float opacity;
  float scale[3];
  float rot[4];
  float feature[kFeatureDim];
  float log_alpha;
  float confidence;
  std::uint32_t label;

  /// \brief A neutral Gaussian at the origin: identity rotation, unit scale (log 0), opacity
  /// logit 0, zero SH and features, log_alpha 0, confidence 0, unlabelled.
  GaussianPoint();
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief Whether every field of `a` and `b` holds the same bits (padding ignored; NaNs with
/// equal bits compare equal). This is the equality of lossless round trips.
bool bitwiseEqual(const GaussianPoint& a, const GaussianPoint& b);

}  // namespace sadsplat

// clang-format off
POINT_CLOUD_REGISTER_POINT_STRUCT(sadsplat::GaussianPoint,
  (float, x, x)
  (float, y, y)
  (float, z, z)
  (float, nx, nx)
  (float, ny, ny)
  (float, nz, nz)
  (float[3], f_dc, f_dc)
  (float[45], f_rest, f_rest)
  (float, opacity, opacity)
  (float[3], scale, scale)
  (float[4], rot, rot)
  (float[32], feature, feature)
  (float, log_alpha, log_alpha)
  (float, confidence, confidence)
  (std::uint32_t, label, label)
)
// clang-format on
