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
/// | .spz      | Niantic SPZ v2-v4 (lossy; v3 written)| -                                   |
/// | .sog      | PlayCanvas SOG v2 (read only)       | -                                   |
/// | .compressed.ply | PlayCanvas compressed PLY (read only, told from a 3DGS PLY by its header) | - |

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>

#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/io/gaussian_checks.h"

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

/// \brief Reads a Gaussian cloud from any of the formats above.
/// \param[out] report if not null, what the value checks changed (gaussian_checks.h)
/// \throws sadsplat::Error naming the file (and field) when it is not one
pcl::PointCloud<GaussianPoint> readGaussians(const std::string& path,
                                             GaussianReadReport* report = nullptr);

/// \brief Writes a Gaussian cloud; the extension (.ply, .pcd) chooses the format. Atomic.
void writeGaussians(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud);

/// \brief How `convertCloudFile` writes formats with choices.
struct ConvertOptions {
  int spz_version = 3;  ///< 2, 3 or 4 (splat_formats.h)
};

/// \brief Converts a cloud file to another format (the extensions choose), atomically. A
/// semantic cloud stays a semantic cloud; an `.spz` input's antialiasing flag is kept in an
/// `.spz` output.
/// \return a one-line note of what reading changed ("3 infinite opacities clamped"), or ""
std::string convertCloudFile(const std::string& in, const std::string& out,
                             const ConvertOptions& options = {});

/// \brief Reads a plain semantic cloud from a .ply or .pcd file.
pcl::PointCloud<pcl::PointXYZRGBL> readSemanticCloud(const std::string& path);

/// \brief Writes a plain semantic cloud; the extension (.ply, .pcd) chooses the format. Atomic.
void writeSemanticCloud(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud);

}  // namespace io
}  // namespace sadsplat
