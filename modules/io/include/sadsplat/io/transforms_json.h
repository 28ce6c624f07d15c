#pragma once
/// \file transforms_json.h
/// \brief Posed images as nerfstudio and instant-ngp describe them (`transforms.json`), read into
/// the COLMAP model the importer already understands.
///
/// The format (nerfstudio's "Data conventions" page and instant-ngp's `colmap2nerf.py`):
/// `frames[]` with `file_path` (relative to the file's folder; Blender-style paths without an
/// extension get `.png`) and `transform_matrix`, a 4x4 camera-to-world matrix in OpenGL axes
/// (x right, y up, z back: the camera looks along -z). Intrinsics at the top level or per frame
/// (a frame's own value wins): `fl_x`, `fl_y` (default `fl_x`), or `camera_angle_x` /
/// `camera_angle_y` (full field of view in radians); `cx`, `cy` (default the image centre), `w`,
/// `h`; `camera_model` "OPENCV" (default) with `k1 k2 p1 p2` and optionally `k3`, or
/// "OPENCV_FISHEYE" with `k1..k4`. nerfstudio's `ply_file_path` names the sparse points.
/// Pixel centres are at +0.5, as in COLMAP. A frame's `mask_path` (nerfstudio) names its mask.
/// Not read: depth, `aabb_scale`,
/// `applied_transform` (the poses and the points are already in one frame).

#include <array>
#include <functional>
#include <map>
#include <string>

#include "sadsplat/io/colmap.h"

namespace sadsplat {
namespace io {

/// \brief A posed image set from a transforms.json.
struct TransformsJson {
  /// One camera per distinct set of intrinsics, one image per frame (world-to-camera in OpenCV
  /// axes, as COLMAP's), the points of `ply_file_path` (no tracks) or none.
  ColmapModel model;
  /// The folder the images' names are relative to: `<dir>/images` when every frame lies in it
  /// (nerfstudio's layout, so names match labels/<stem>.png as in COLMAP scenes), else `<dir>`.
  std::string image_dir;
  /// image name -> its mask (`mask_path`, relative to the file's folder, made absolute)
  std::map<std::string, std::string> mask_paths;
};

/// \brief Size (width, height) of the image at a path; asked only for frames without `w` / `h`.
using ImageSizeOf = std::function<std::array<int, 2>(const std::string& image_path)>;

/// \brief Reads a transforms.json.
/// \throws sadsplat::Error naming the file, the frame and the field: missing or non-finite
/// numbers, a transform that is not a rigid 4x4 matrix, an unknown camera model, distortion
/// the camera model cannot express, no frames, or a duplicate image
TransformsJson readTransformsJson(const std::string& path, const ImageSizeOf& image_size);

}  // namespace io
}  // namespace sadsplat
