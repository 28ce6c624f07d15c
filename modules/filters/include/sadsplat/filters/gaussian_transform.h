#pragma once
/// \file gaussian_transform.h
/// \brief A rigid motion of a Gaussian cloud, as pcl::transformPointCloud moves points: centres,
/// orientations and the view-dependent colour (spherical harmonics) move together, so that the
/// moved cloud renders from the moved cameras exactly as the cloud did from the old ones.

#include <pcl/point_cloud.h>

#include <Eigen/Core>
#include <array>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace filters {

/// \brief The matrices that rotate the SH coefficients of degrees 1, 2 and 3 (3x3, 5x5, 7x7, in
/// the 3DGS basis order) under the rotation `rotation`: c' = M_l c for each colour channel, so
/// that sum_k c'_k Y_k(R d) = sum_k c_k Y_k(d) for every direction d.
/// \throws sadsplat::Error when `rotation` is not a rotation (orthonormal, determinant +1)
std::array<Eigen::MatrixXd, 3> shRotationMatrices(const Eigen::Matrix3d& rotation);

/// \brief x -> R x + t for every Gaussian: centre moved, quaternion turned (q' = q_R q), SH
/// degrees 1..3 rotated; scales, opacity, SH degree 0, feature, gate, confidence and label kept.
/// \throws sadsplat::Error when `rotation` is not a rotation (a mirror would turn the Gaussians
/// inside out: their quaternions cannot express it)
void transformGaussians(const pcl::PointCloud<GaussianPoint>& in,
                        pcl::PointCloud<GaussianPoint>& out, const Eigen::Matrix3d& rotation,
                        const Eigen::Vector3d& translation = Eigen::Vector3d::Zero());

}  // namespace filters
}  // namespace sadsplat
