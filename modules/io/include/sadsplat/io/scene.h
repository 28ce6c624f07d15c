#pragma once
/// \file scene.h
/// \brief An imported scene in memory: classes, posed pinhole views with images, label maps and
/// masks, and the sparse points. Plain data, no OpenCV: the GPU build reads it from the cache.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/common/class_info.h"

namespace sadsplat {
namespace io {

/// \brief Label value of a pixel with no class (sky, outside the undistorted image, unlabelled).
constexpr std::uint8_t kIgnoreLabel = 255;

/// \brief An undistorted pinhole camera with its pose, in COLMAP conventions:
/// x_cam = R(qvec) x_world + tvec, qvec = (w, x, y, z), pixel centres at +0.5.
struct PinholeCamera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 4> qvec{1, 0, 0, 0};
  std::array<double, 3> tvec{0, 0, 0};
};

/// \brief An 8-bit image, row-major, channels interleaved.
struct Image8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<std::uint8_t> pixels;  ///< width * height * channels bytes

  bool empty() const { return pixels.empty(); }
  std::uint8_t at(int x, int y, int c = 0) const {
    return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c];
  }
};

/// \brief One posed image of the scene.
struct View {
  std::string name;       ///< image file name, relative to images/
  PinholeCamera camera;   ///< already undistorted and resized to the image below
  Image8 rgb;             ///< 3 channels
  Image8 mask;            ///< 1 channel: 255 = valid pixel, 0 = outside the undistorted image
  Image8 labels;          ///< 1 channel class ids (kIgnoreLabel = none); empty if unlabelled
  bool train = false;     ///< in the training set
  bool test = false;      ///< in the test set
  bool labelled = false;  ///< a training view whose label map supervises training
};

/// \brief One sparse (SfM) point.
struct ScenePoint {
  std::array<float, 3> xyz{0, 0, 0};
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
};

/// \brief A whole scene.
struct Scene {
  std::string source;               ///< where it was imported from (informational)
  std::vector<ClassInfo> classes;
  std::vector<View> views;          ///< sorted by name
  std::vector<ScenePoint> points;
};

/// \brief The class list and split of a scene directory, readable without OpenCV.
struct SplitInfo {
  std::vector<std::string> train;     ///< image names
  std::vector<std::string> test;      ///< image names
  std::vector<std::string> labelled;  ///< subset of train whose label maps supervise training
};

/// \brief Reads classes.json: {"classes": [{"name": s, "color": [r, g, b], "prompt": s}, ...]}.
/// `prompt` is optional (defaults to the name). Names must be unique; at most 255 classes.
/// \throws sadsplat::Error naming the file and the field
std::vector<ClassInfo> readClassesJson(const std::string& path);

/// \brief Reads split.json: {"train": [names], "test": [names], "labelled": [names]}.
/// \throws sadsplat::Error naming the file and the field
SplitInfo readSplitJson(const std::string& path);

/// \brief Writes classes.json (atomically) in the format readClassesJson reads.
void writeClassesJson(const std::string& path, const std::vector<ClassInfo>& classes);
/// \brief Writes split.json (atomically) in the format readSplitJson reads.
void writeSplitJson(const std::string& path, const SplitInfo& split);

}  // namespace io
}  // namespace sadsplat
