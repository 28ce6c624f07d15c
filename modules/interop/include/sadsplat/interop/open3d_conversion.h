#pragma once
/// \file open3d_conversion.h
/// \brief sadsplat clouds as Open3D point clouds, in C++.
///
/// A Gaussian cloud becomes an `open3d::t::geometry::PointCloud` (CPU) whose attributes carry
/// the 3DGS PLY names, so that it matches what `open3d.t.io.read_point_cloud` makes of
/// sadsplat's model.ply: `positions` and `normals` (N x 3, Float32), one N x 1 Float32 attribute
/// per scalar field (`f_dc_0..2`, `f_rest_0..44`, `opacity`, `scale_0..2`, `rot_0..3`,
/// `feature_0..31`, `log_alpha`, `confidence`) and `label` (N x 1 Int32, -1: no class). The
/// conversion back is its exact inverse (bit for bit). f_rest keeps GaussianPoint's
/// channel-major order, as in the PLY.

#include <open3d/geometry/PointCloud.h>
#include <open3d/t/geometry/PointCloud.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <memory>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace interop {

/// \brief Every field of every Gaussian as named attributes of an Open3D tensor point cloud.
open3d::t::geometry::PointCloud toOpen3d(const pcl::PointCloud<GaussianPoint>& cloud);

/// \brief The Gaussians of an Open3D tensor point cloud with toOpen3d's attributes. Required:
/// positions, f_dc_0..2, opacity, scale_0..2, rot_0..3; the others keep GaussianPoint's defaults
/// when absent (f_rest only when all 45 are there).
/// \throws sadsplat::Error naming the attribute when a required one is missing or has the wrong
/// shape or type
pcl::PointCloud<GaussianPoint> fromOpen3d(const open3d::t::geometry::PointCloud& cloud);

/// \brief A plain semantic cloud as a legacy Open3D point cloud: points and colours (the class
/// colours in [0, 1]); the labels are returned in `labels` when given (-1: no class).
std::shared_ptr<open3d::geometry::PointCloud> toOpen3dLegacy(
    const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, std::vector<int>* labels = nullptr);

}  // namespace interop
}  // namespace sadsplat
