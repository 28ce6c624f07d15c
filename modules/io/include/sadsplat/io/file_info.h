#pragma once
/// \file file_info.h
/// \brief Human-readable summaries of the files sadsplat reads (`sadsplat info`).

#include <string>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {

/// \brief A multi-line summary of a 3DGS PLY, a PCD, a scene directory or a scene cache:
/// counts, SH degree, bounding box, classes, views.
/// \throws sadsplat::Error if the file is of none of these kinds or is invalid
std::string describeFile(const std::string& path);

/// \brief describeFile's summary of the scene cache at `path` whose contents are `scene`.
std::string describeSceneCache(const std::string& path, const Scene& scene);

/// \brief The cameras of a scene cache or scene directory as CSV, one line per view after a
/// header: name, width, height, fx, fy, cx, cy (pixels, centres at +0.5), qw qx qy qz and
/// tx ty tz (world to camera, COLMAP's convention), train / test roles.
/// \throws sadsplat::Error if `path` is neither or is invalid
std::string describeCameras(const std::string& path);

}  // namespace io
}  // namespace sadsplat
