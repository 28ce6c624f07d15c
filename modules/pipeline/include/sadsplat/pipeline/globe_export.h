#pragma once
/// \file globe_export.h
/// \brief A trained model for the globe (`sadsplat tiles`, `convert model.glb`): the model turned
/// into an upright frame and, when georeferenced, placed on Earth.
///
/// Frame: a georeferenced model is already east-north-up metres around the georeference's origin
/// (georeference.json in the run directory or beside the model file); the tileset's root transform
/// is that ENU frame in ECEF. Otherwise the model is turned so that the scene's up (geo::sceneUp of
/// the run's scene: minus the cameras' mean viewing direction) is z; a model file without its run
/// takes -y as up (the 3DGS / COLMAP camera convention: y down). Such a tileset is local (no
/// transform): a client places it.

#include <array>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "sadsplat/common/class_info.h"
#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/io/georeference.h"
#include "sadsplat/io/gltf_splats.h"

#include <pcl/point_cloud.h>

namespace sadsplat {
namespace pipeline {

/// \brief A model in an upright (z-up) frame, with what places it.
struct UprightModel {
  pcl::PointCloud<GaussianPoint> cloud;  ///< z up
  std::vector<ClassInfo> classes;
  std::optional<io::Georeference> georeference;
  std::string frame;  ///< one line: which frame and why
};

/// \brief Reads a run directory's model.ply (or a model file) with classes.json and
/// georeference.json beside it, turned upright (see the file comment).
/// \throws sadsplat::Error naming the file that cannot be read
UprightModel openUprightModel(const std::string& model_or_run);

/// \brief `sadsplat tiles` options.
struct TilesExportOptions {
  std::size_t max_splats = 65536;  ///< splat budget of a tile
  bool spz = true;                 ///< SPZ-compressed content (else plain accessors)
  int sh_degree = 3;
  bool class_aware = true;         ///< levels of detail merge only Gaussians of one class
  /// every splat drawn in its class's colour (classes.json; unlabelled: grey) with no
  /// view-dependent colour: the class map in 3D for clients that cannot style splats by feature
  /// ID (CesiumJS 1.145 does not)
  bool color_by_class = false;
};

/// \brief Sets every Gaussian's colour to its class's (unlabelled: grey), SH degrees 1..3 zero.
void colorByClass(pcl::PointCloud<GaussianPoint>& cloud, const std::vector<ClassInfo>& classes);

/// \brief Writes the 3D Tiles tileset of `model_or_run` into `out_dir`; returns a summary
/// (tiles, depth, splats, bytes, where it sits on Earth or that it is local).
/// \throws sadsplat::Error on unreadable input or unwritable output
std::string exportTiles(const std::string& model_or_run, const std::string& out_dir,
                        const TilesExportOptions& options, std::ostream* progress = nullptr);

/// \brief Writes `model_or_run` as one `.glb` (glTF axes of the upright frame); returns a line
/// naming the frame.
std::string exportGlb(const std::string& model_or_run, const std::string& out_path,
                      io::GltfSplatOptions options);

}  // namespace pipeline
}  // namespace sadsplat
