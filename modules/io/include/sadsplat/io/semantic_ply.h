#pragma once
/// \file semantic_ply.h
/// \brief The plain semantic cloud (pcl::PointXYZRGBL) as a PLY point cloud: `x y z` float,
/// `red green blue` uchar (the class colour) and `label` int (-1: no class).
///
/// Ordinary point-cloud tools read it: CloudCompare and MeshLab show the class colours, Open3D
/// (`o3d.t.io.read_point_cloud`) keeps `label` as an attribute (it skips `uint` properties).

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <string>

namespace sadsplat {
namespace io {

/// \brief Writes a semantic cloud as a binary little-endian PLY (atomically).
/// \throws sadsplat::Error naming the file when it cannot be written
void writeSemanticPly(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud);

/// \brief Reads a PLY with `x y z`, `red green blue` and `label` vertex properties (any PLY
/// scalar types, ascii or binary; other elements and properties are skipped).
/// \throws sadsplat::Error naming the file and property when it is missing or invalid
pcl::PointCloud<pcl::PointXYZRGBL> readSemanticPly(const std::string& path);

/// \brief Reads any PLY point cloud: `x y z` required, `red green blue` (grey 128 when absent)
/// and `label` (-1 when absent) optional; other elements and properties are skipped.
/// \throws sadsplat::Error naming the file and property when it is missing or invalid
pcl::PointCloud<pcl::PointXYZRGBL> readPointCloudPly(const std::string& path);

/// \brief Whether the PLY at `path` is a semantic cloud (it has `label` and `red`, but no
/// `f_dc_0`): the header alone is read.
/// \throws sadsplat::Error naming the file when it is missing or its header is invalid
bool isSemanticPly(const std::string& path);

}  // namespace io
}  // namespace sadsplat
