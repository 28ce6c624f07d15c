#pragma once
/// \file view_model.h
/// \brief What a view shows: a Gaussian cloud with its class list and, for a training run, the
/// cameras of its scene.

#include <pcl/point_cloud.h>

#include <string>
#include <utility>
#include <vector>

#include "sadsplat/common/class_info.h"
#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/io/scene.h"
#include "sadsplat/io/splat_frame.h"

namespace sadsplat {
namespace viz {

/// \brief A model to look at.
struct ViewModel {
  std::string name;                          ///< shown in the window (file or run name)
  pcl::PointCloud<GaussianPoint> gaussians;  ///< what is drawn
  std::vector<ClassInfo> classes;            ///< empty when no class list was found
  bool semantic_only = false;  ///< read from a plain semantic cloud (x y z colour label only)
  bool has_semantic = false;   ///< the file has sadsplat's semantic fields (label, gate, ...)
  /// The scene's views (name, camera) when the model is a run whose scene is a cache.
  std::vector<std::pair<std::string, io::PinholeCamera>> cameras;
  /// Renders the model through a camera (the splat mode); null: the model can only be shown as
  /// discs (`--mode points`). The viewer's caller sets it (pipeline::SplatFrames), since this
  /// module has no rasterizer.
  io::FrameSource frames;
};

/// \brief Loads a model to view: a run directory (its model.ply, classes.json and the cameras of
/// the scene named in run.json when that is a scene cache), a Gaussian .ply / .pcd (with a
/// classes.json beside it, if any), or a plain semantic .ply / .pcd (points drawn as small
/// opaque splats of their class colour).
/// \throws sadsplat::Error naming the path when it is none of these
ViewModel loadViewModel(const std::string& path);

}  // namespace viz
}  // namespace sadsplat
