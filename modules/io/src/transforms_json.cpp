#include "sadsplat/io/transforms_json.h"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/semantic_ply.h"
#include "json_field.h"

namespace sadsplat {
namespace io {
namespace {

using nlohmann::json;

std::string folderOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

// A frame's value of `key`, else the file's, else none.
const json* lookUp(const json& frame, const json& top, const char* key) {
  if (frame.contains(key) && !frame[key].is_null()) return &frame[key];
  if (top.contains(key) && !top[key].is_null()) return &top[key];
  return nullptr;
}

class FrameReader {
 public:
  FrameReader(const std::string& path, const json& top, const json& frame, std::string where)
      : path_(path), top_(top), frame_(frame), where_(std::move(where)) {}

  bool has(const char* key) const { return lookUp(frame_, top_, key) != nullptr; }

  double number(const char* key) const {
    const json* v = lookUp(frame_, top_, key);
    if (v == nullptr) throw Error(path_, where_ + " " + key, "a number", "missing");
    return checked(*v, key);
  }
  double number(const char* key, double fallback) const {
    const json* v = lookUp(frame_, top_, key);
    return v == nullptr ? fallback : checked(*v, key);
  }
  std::string text(const char* key, const std::string& fallback) const {
    const json* v = lookUp(frame_, top_, key);
    if (v == nullptr) return fallback;
    if (!v->is_string()) throw Error(path_, where_ + " " + key, "a string", v->dump());
    return v->get<std::string>();
  }
  const std::string& where() const { return where_; }

 private:
  double checked(const json& v, const char* key) const {
    if (!v.is_number()) throw Error(path_, where_ + " " + key, "a number", v.dump());
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw Error(path_, where_ + " " + key, "a finite number", v.dump());
    return d;
  }
  const std::string& path_;
  const json& top_;
  const json& frame_;
  std::string where_;
};

// The camera-to-world matrix in OpenGL axes -> COLMAP's world-to-camera (OpenCV axes).
void poseOf(const std::string& path, const std::string& where, const json& m, ColmapImage* image) {
  if (!m.is_array() || m.size() < 3 || m.size() > 4) {
    throw Error(path, where + " transform_matrix", "a 4x4 (or 3x4) array of numbers",
                m.is_null() ? "missing" : m.dump().substr(0, 80));
  }
  Eigen::Matrix3d r;
  Eigen::Vector3d centre;
  for (int i = 0; i < 3; ++i) {
    if (!m[i].is_array() || m[i].size() != 4) {
      throw Error(path, where + " transform_matrix row " + std::to_string(i), "4 numbers",
                  m[i].dump().substr(0, 80));
    }
    for (int j = 0; j < 4; ++j) {
      if (!m[i][j].is_number() || !std::isfinite(m[i][j].get<double>())) {
        throw Error(path, where + " transform_matrix", "finite numbers", m[i][j].dump());
      }
      (j < 3 ? r(i, j) : centre(i)) = m[i][j].get<double>();
    }
  }
  // Rigid: the tools write rotation matrices; a scale hidden in them would skew every ray.
  const double orthogonality =
      (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > 1e-3 || r.determinant() < 0) {
    std::ostringstream got;
    got << "max |R^T R - I| " << orthogonality << ", det " << r.determinant();
    throw Error(path, where + " transform_matrix",
                "a rotation (orthonormal, det +1) and a translation", got.str());
  }
  // OpenGL camera axes (y up, z back) -> OpenCV's (y down, z forward): flip the y and z columns.
  const Eigen::Matrix3d c2w = r * Eigen::Vector3d(1, -1, -1).asDiagonal();
  const Eigen::Matrix3d w2c = c2w.transpose();
  Eigen::Quaterniond q(w2c);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1;
  image->qvec = {q.w(), q.x(), q.y(), q.z()};
  const Eigen::Vector3d t = -w2c * centre;
  image->tvec = {t.x(), t.y(), t.z()};
}

ColmapCamera cameraOf(const std::string& path, const FrameReader& f, int width, int height) {
  ColmapCamera c;
  c.width = width;
  c.height = height;
  double fx, fy;
  if (f.has("fl_x")) {
    fx = f.number("fl_x");
    fy = f.number("fl_y", fx);
  } else if (f.has("camera_angle_x")) {
    // instant-ngp and the NeRF synthetic scenes: the full horizontal field of view.
    const double ax = f.number("camera_angle_x");
    if (!(ax > 0 && ax < M_PI)) {
      throw Error(path, f.where() + " camera_angle_x", "an angle in (0, pi) radians",
                  std::to_string(ax));
    }
    fx = 0.5 * width / std::tan(0.5 * ax);
    fy = fx;
    if (f.has("camera_angle_y")) {
      const double ay = f.number("camera_angle_y");
      if (!(ay > 0 && ay < M_PI)) {
        throw Error(path, f.where() + " camera_angle_y", "an angle in (0, pi) radians",
                    std::to_string(ay));
      }
      fy = 0.5 * height / std::tan(0.5 * ay);
    }
  } else {
    throw Error(path, f.where() + " fl_x", "a focal length (fl_x, or camera_angle_x)", "missing");
  }
  // As the scene cache requires (PinholeCamera::validate): a focal length below a thousandth of
  // a pixel is no camera.
  if (!(fx >= 1e-3 && fy >= 1e-3 && std::isfinite(fx) && std::isfinite(fy))) {
    std::ostringstream got;
    got << fx << " / " << fy;
    throw Error(path, f.where() + " fl_x / fl_y", "finite focal lengths of at least 0.001 px",
                got.str());
  }
  const double cx = f.number("cx", width / 2.0), cy = f.number("cy", height / 2.0);
  const std::string model = f.text("camera_model", "OPENCV");
  const double k1 = f.number("k1", 0), k2 = f.number("k2", 0), k3 = f.number("k3", 0),
               k4 = f.number("k4", 0), p1 = f.number("p1", 0), p2 = f.number("p2", 0);
  if (model == "OPENCV_FISHEYE") {
    if (p1 != 0 || p2 != 0) {
      throw Error(path, f.where() + " p1 / p2", "0 for OPENCV_FISHEYE (it has no tangential terms)",
                  std::to_string(p1) + " / " + std::to_string(p2));
    }
    c.model = CameraModel::kOpenCVFisheye;
    c.params = {fx, fy, cx, cy, k1, k2, k3, k4};
  } else if (model == "OPENCV" || model == "PINHOLE") {
    if (k4 != 0) {
      throw Error(path, f.where() + " k4",
                  "0 for OPENCV (nerfstudio's k4 is an r^8 term OpenCV has no equivalent of)",
                  std::to_string(k4));
    }
    if (k3 != 0) {
      c.model = CameraModel::kFullOpenCV;
      c.params = {fx, fy, cx, cy, k1, k2, p1, p2, k3, 0, 0, 0};
    } else if (k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0) {
      c.model = CameraModel::kOpenCV;
      c.params = {fx, fy, cx, cy, k1, k2, p1, p2};
    } else {
      c.model = CameraModel::kPinhole;
      c.params = {fx, fy, cx, cy};
    }
  } else {
    throw Error(path, f.where() + " camera_model", "OPENCV or OPENCV_FISHEYE", model);
  }
  return c;
}

std::string normalisedRelative(const std::string& file_path) {
  std::string p = file_path;
  while (p.rfind("./", 0) == 0) p = p.substr(2);
  return p;
}

}  // namespace

TransformsJson readTransformsJson(const std::string& path, const ImageSizeOf& image_size) {
  requireRegularFile(path);
  json top;
  top = parseJson(readWholeFile(path), path);
  if (!top.is_object() || !top.contains("frames") || !top["frames"].is_array()) {
    throw Error(path, "frames", "an array of frames (nerfstudio / instant-ngp transforms.json)",
                top.is_object() && top.contains("frames") ? top["frames"].type_name() : "missing");
  }
  const json& frames = top["frames"];
  if (frames.empty()) throw Error(path, "frames", "at least one frame", "none");
  const std::string dir = folderOf(path);

  // Image paths first: they decide the folder names are relative to.
  std::vector<std::string> files;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::string where = "frame " + std::to_string(i);
    const json& fr = frames[i];
    if (!fr.is_object() || !fr.contains("file_path") || !fr["file_path"].is_string()) {
      throw Error(path, where + " file_path", "an image path relative to the file", "missing");
    }
    std::string file = normalisedRelative(fr["file_path"].get<std::string>());
    if (file.empty() || file[0] == '/') {
      throw Error(path, where + " file_path", "an image path relative to the file's folder",
                  "\"" + file + "\"");
    }
    // The NeRF synthetic scenes name their PNGs without the extension.
    if (!pathExists(dir + "/" + file) && pathExists(dir + "/" + file + ".png")) file += ".png";
    files.push_back(file);
  }
  const bool in_images = std::all_of(
      files.begin(), files.end(), [](const std::string& f) { return f.rfind("images/", 0) == 0; });
  TransformsJson out;
  out.image_dir = in_images ? dir + "/images" : dir;

  std::map<std::vector<double>, std::uint32_t> camera_ids;  // (model, size, params) -> id
  std::set<std::string> names;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const FrameReader f(path, top, frames[i], "frame " + std::to_string(i));
    const std::string image_path = dir + "/" + files[i];
    int width, height;
    if (f.has("w") && f.has("h")) {
      const double w = f.number("w"), h = f.number("h");
      if (!(w >= 1 && h >= 1 && w <= 1e6 && h <= 1e6) || w != std::floor(w) || h != std::floor(h)) {
        throw Error(path, f.where() + " w / h", "a size of 1..1000000 whole pixels",
                    std::to_string(w) + "x" + std::to_string(h));
      }
      width = static_cast<int>(w);
      height = static_cast<int>(h);
    } else {
      if (!pathExists(image_path)) {
        throw Error(path, f.where() + " file_path",
                    "an existing image (its size is needed: no w/h)", image_path + " missing");
      }
      const auto size = image_size(image_path);
      width = size[0];
      height = size[1];
    }
    if (width <= 0 || height <= 0) {
      throw Error(path, f.where() + " w / h", "a positive image size",
                  std::to_string(width) + "x" + std::to_string(height));
    }
    ColmapCamera camera = cameraOf(path, f, width, height);
    std::vector<double> key = {static_cast<double>(camera.model), double(width), double(height)};
    key.insert(key.end(), camera.params.begin(), camera.params.end());
    auto it = camera_ids.find(key);
    if (it == camera_ids.end()) {
      camera.id = static_cast<std::uint32_t>(camera_ids.size() + 1);
      it = camera_ids.emplace(key, camera.id).first;
      out.model.cameras.push_back(camera);
    }
    ColmapImage image;
    image.id = static_cast<std::uint32_t>(i + 1);
    image.camera_id = it->second;
    image.name = in_images ? files[i].substr(7) : files[i];
    if (!names.insert(image.name).second) {
      throw Error(path, f.where() + " file_path", "each image once", image.name + " twice");
    }
    if (frames[i].contains("mask_path")) {
      const json& m = frames[i]["mask_path"];
      const std::string mask = m.is_string() ? normalisedRelative(m.get<std::string>()) : "";
      if (mask.empty() || mask[0] == '/') {
        throw Error(path, f.where() + " mask_path", "a mask path relative to the file's folder",
                    m.dump());
      }
      out.mask_paths[image.name] = dir + "/" + mask;
    }
    poseOf(path, f.where(),
           frames[i].contains("transform_matrix") ? frames[i]["transform_matrix"] : json(), &image);
    out.model.images.push_back(std::move(image));
  }

  if (top.contains("ply_file_path") && top["ply_file_path"].is_string()) {
    const std::string ply = dir + "/" + normalisedRelative(top["ply_file_path"].get<std::string>());
    if (!pathExists(ply))
      throw Error(path, "ply_file_path", "an existing PLY point cloud", ply + " missing");
    const auto cloud = readPointCloudPly(ply);
    for (const auto& p : cloud) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
      ColmapPoint3D point;
      point.id = out.model.points.size() + 1;
      point.xyz = {p.x, p.y, p.z};
      point.rgb = {p.r, p.g, p.b};
      out.model.points.push_back(std::move(point));
    }
  }
  return out;
}

}  // namespace io
}  // namespace sadsplat
