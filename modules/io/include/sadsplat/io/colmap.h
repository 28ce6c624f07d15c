#pragma once
/// \file colmap.h
/// \brief COLMAP sparse models (cameras, images, points3D), text and binary, read and written.
///
/// Conventions are COLMAP's: an image's (qvec, tvec) maps world to camera,
/// x_cam = R(qvec) * x_world + tvec, with qvec = (w, x, y, z); camera axes x right, y down,
/// z forward; pixel centres at +0.5.

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief The COLMAP camera models sadsplat reads, with COLMAP's numeric ids.
enum class CameraModel : int {
  kSimplePinhole = 0,  ///< f, cx, cy
  kPinhole = 1,        ///< fx, fy, cx, cy
  kSimpleRadial = 2,   ///< f, cx, cy, k
  kRadial = 3,         ///< f, cx, cy, k1, k2
  kOpenCV = 4,         ///< fx, fy, cx, cy, k1, k2, p1, p2
  kOpenCVFisheye = 5,  ///< fx, fy, cx, cy, k1, k2, k3, k4 (equidistant, OpenCV's cv::fisheye)
  kFullOpenCV = 6,     ///< fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6 (rational)
};

/// \brief Whether a model has separate fx and fy (its params[1] is fy, not cx).
bool cameraModelHasFy(CameraModel model);

/// \brief COLMAP's name of a model ("PINHOLE", ...).
const char* cameraModelName(CameraModel model);
/// \brief Number of parameters of a model.
int cameraModelNumParams(CameraModel model);

struct ColmapCamera {
  std::uint32_t id = 0;
  CameraModel model = CameraModel::kPinhole;
  std::uint64_t width = 0;
  std::uint64_t height = 0;
  std::vector<double> params;  ///< in COLMAP's order for the model
};

struct ColmapPoint2D {
  double x = 0, y = 0;
  std::int64_t point3d_id = -1;  ///< -1: no 3D point
};

struct ColmapImage {
  std::uint32_t id = 0;
  std::array<double, 4> qvec{1, 0, 0, 0};  ///< world-to-camera rotation (w, x, y, z)
  std::array<double, 3> tvec{0, 0, 0};     ///< world-to-camera translation
  std::uint32_t camera_id = 0;
  std::string name;  ///< file name relative to the images folder
  std::vector<ColmapPoint2D> points2d;
};

struct ColmapPoint3D {
  std::uint64_t id = 0;
  std::array<double, 3> xyz{0, 0, 0};
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
  double error = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> track;  ///< (image id, point2D index)
};

/// \brief A whole sparse model; order is file order.
struct ColmapModel {
  std::vector<ColmapCamera> cameras;
  std::vector<ColmapImage> images;
  std::vector<ColmapPoint3D> points;
};

/// \brief Reads `dir`/{cameras,images,points3D}.bin if all three exist, else the .txt files.
///
/// Validates: every number parses and is finite, camera models are known with the right
/// number of parameters, sizes are positive, ids are unique, images name known cameras.
/// \throws sadsplat::Error naming the file, the line or record and the expectation
ColmapModel readColmapModel(const std::string& dir);

/// \brief Writes the model as COLMAP text files into `dir` (atomically, file by file).
void writeColmapText(const std::string& dir, const ColmapModel& model);
/// \brief Writes the model as COLMAP binary files into `dir` (atomically, file by file).
void writeColmapBinary(const std::string& dir, const ColmapModel& model);

}  // namespace io
}  // namespace sadsplat
