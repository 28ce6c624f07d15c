#pragma once
/// \file las_export.h
/// \brief Clouds as LAS 1.4 (point format 7) on the map: Gaussian centres with their base colour
/// (SH degree 0) or semantic points with their class colour, the class as its ASPRS code, in the
/// UTM zone of the scene's georeference (exact, through PROJ) or in local metres.

#include <optional>
#include <string>
#include <vector>

#include "sadsplat/common/class_info.h"
#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/georeference.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace sadsplat {
namespace geo {

/// \brief What a LAS export needs besides the cloud.
struct LasExportOptions {
  std::vector<ClassInfo> classes;                ///< names for the ASPRS mapping (may be empty)
  std::optional<io::Georeference> georeference;  ///< none: local metres
  std::string classification_map;                ///< JSON {"class": code} overriding defaults
  /// Without a georeference: the points through this frame (the map's local metres, z up, as
  /// `ortho` draws them) instead of the scene's own axes; none: the scene's axes.
  std::optional<MapFrame> local_frame;
};

/// \brief Writes the Gaussians' centres; returns a one-line summary (points, CRS, codes used).
/// A Gaussian without a class gets code 1 (unclassified); a model without classes, 0.
/// \throws sadsplat::Error (bad map, a georeference without GDAL, an unwritable path)
std::string writeGaussiansLas(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
                              const LasExportOptions& options);

/// \brief Writes a semantic cloud (centre, class colour, class id); summary as above.
std::string writeSemanticLas(const std::string& path,
                             const pcl::PointCloud<pcl::PointXYZRGBL>& cloud,
                             const LasExportOptions& options);

/// \brief The folder of a model file, or a run directory itself: where its classes.json,
/// georeference.json and run.json lie.
std::string modelFolder(const std::string& model_path);

/// \brief For a model file (or run directory) MODEL: the classes.json and georeference.json next
/// to it (a run directory has both), for `convert` / `extract`.
LasExportOptions lasOptionsBeside(const std::string& model_path,
                                  const std::string& classification_map = "");

}  // namespace geo
}  // namespace sadsplat
