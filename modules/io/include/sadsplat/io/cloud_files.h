#pragma once
/// \file cloud_files.h
/// \brief Reading and writing the clouds sadsplat makes, whatever the file format: the
/// extension chooses the codec, the header tells a Gaussian cloud from a plain semantic one.
///
/// | extension | Gaussian cloud (GaussianPoint)      | semantic cloud (pcl::PointXYZRGBL)  |
/// |-----------|-------------------------------------|-------------------------------------|
/// | .ply      | 3DGS PLY + semantic properties      | x y z red green blue label          |
/// | .pcd      | PCD, every GaussianPoint field      | PCD x y z rgba label                |
/// | .splat    | 32-byte web viewer records (lossy)  | -                                   |
/// | .spz      | Niantic SPZ v3, gzip (lossy)        | -                                   |

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {

/// \brief What a cloud file holds.
enum class CloudKind {
  kGaussians,  ///< semantic 3D Gaussians (GaussianPoint)
  kSemantic    ///< a plain semantic point cloud (x y z, colour, label)
};

/// \brief Says what the cloud file at `path` holds (reads its header).
/// \throws sadsplat::Error naming the file when it is neither, or is not a .ply / .pcd
CloudKind cloudKind(const std::string& path);

/// \brief Reads a Gaussian cloud from a .ply or .pcd file.
/// \throws sadsplat::Error naming the file (and field) when it is not one
pcl::PointCloud<GaussianPoint> readGaussians(const std::string& path);

/// \brief Writes a Gaussian cloud; the extension (.ply, .pcd) chooses the format. Atomic.
void writeGaussians(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud);

/// \brief Reads a plain semantic cloud from a .ply or .pcd file.
pcl::PointCloud<pcl::PointXYZRGBL> readSemanticCloud(const std::string& path);

/// \brief Writes a plain semantic cloud; the extension (.ply, .pcd) chooses the format. Atomic.
void writeSemanticCloud(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud);

}  // namespace io
}  // namespace sadsplat
