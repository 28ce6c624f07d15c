#include "sadsplat/io/colmap.h"

#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {
namespace {

bool knownModel(int id) { return id >= 0 && id <= 6; }

bool modelFromName(const std::string& name, CameraModel* model) {
  for (int id = 0; id <= 6; ++id) {
    if (name == cameraModelName(static_cast<CameraModel>(id))) {
      *model = static_cast<CameraModel>(id);
      return true;
    }
  }
  return false;
}

void requireFinite(double v, const std::string& file, const std::string& field) {
  if (!std::isfinite(v)) throw Error(file, field, "a finite number", std::to_string(v));
}

void validateCamera(const ColmapCamera& c, const std::string& file, const std::string& where) {
  if (c.width == 0 || c.height == 0) {
    throw Error(file, where + " width/height", "positive sizes",
                std::to_string(c.width) + "x" + std::to_string(c.height));
  }
  const int n = cameraModelNumParams(c.model);
  if (static_cast<int>(c.params.size()) != n) {
    throw Error(file, where + " params",
                std::to_string(n) + " parameters for " + cameraModelName(c.model),
                std::to_string(c.params.size()));
  }
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    requireFinite(c.params[i], file, where + " param " + std::to_string(i));
  }
  if (c.params[0] <= 0 || (cameraModelHasFy(c.model) ? c.params[1] <= 0 : false)) {
    throw Error(file, where + " focal length", "positive", std::to_string(c.params[0]));
  }
}

void validateImage(const ColmapImage& im, const std::string& file, const std::string& where) {
  for (int i = 0; i < 4; ++i) requireFinite(im.qvec[i], file, where + " qvec");
  for (int i = 0; i < 3; ++i) requireFinite(im.tvec[i], file, where + " tvec");
  const double norm = std::sqrt(im.qvec[0] * im.qvec[0] + im.qvec[1] * im.qvec[1] +
                                im.qvec[2] * im.qvec[2] + im.qvec[3] * im.qvec[3]);
  if (norm < 1e-9) throw Error(file, where + " qvec", "a non-zero quaternion", "zero");
  if (im.name.empty()) throw Error(file, where + " name", "an image file name", "empty");
}

// ---- text ------------------------------------------------------------------------------------

class TextLines {
 public:
  explicit TextLines(const std::string& path) : path_(path), text_(readWholeFile(path)) {}

  // Next line that is neither empty nor a comment; false at the end.
  bool nextContent(std::string* line) {
    while (nextRaw(line)) {
      const auto first = line->find_first_not_of(" \t\r");
      if (first == std::string::npos || (*line)[first] == '#') continue;
      return true;
    }
    return false;
  }
  // Next line whatever it holds (COLMAP's points2D line may be empty); false at the end.
  bool nextRaw(std::string* line) {
    if (pos_ >= text_.size()) return false;
    auto eol = text_.find('\n', pos_);
    if (eol == std::string::npos) eol = text_.size();
    *line = text_.substr(pos_, eol - pos_);
    if (!line->empty() && line->back() == '\r') line->pop_back();
    pos_ = eol + 1;
    ++line_no_;
    return true;
  }
  std::string where() const { return "line " + std::to_string(line_no_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string text_;
  std::size_t pos_ = 0;
  int line_no_ = 0;
};

template <typename T>
T parseField(std::istringstream& in, const TextLines& lines, const char* field) {
  T v{};
  if (!(in >> v)) {
    throw Error(lines.path(), lines.where() + " " + field, std::string("a value for ") + field,
                "the end of the line or a non-number");
  }
  return v;
}

double parseDouble(std::istringstream& in, const TextLines& lines, const char* field) {
  std::string token;
  if (!(in >> token)) {
    throw Error(lines.path(), lines.where() + " " + field, std::string("a value for ") + field,
                "the end of the line or a non-number");
  }
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || *end != '\0') {
    throw Error(lines.path(), lines.where() + " " + field, "a number", token);
  }
  requireFinite(v, lines.path(), lines.where() + " " + field);
  return v;
}

std::vector<ColmapCamera> readCamerasText(const std::string& path) {
  TextLines lines(path);
  std::vector<ColmapCamera> cameras;
  std::string line;
  while (lines.nextContent(&line)) {
    std::istringstream in(line);
    ColmapCamera c;
    c.id = parseField<std::uint32_t>(in, lines, "CAMERA_ID");
    const std::string model = parseField<std::string>(in, lines, "MODEL");
    if (!modelFromName(model, &c.model)) {
      throw Error(path, lines.where() + " MODEL",
                  "one of SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, OPENCV_FISHEYE, "
                  "FULL_OPENCV",
                  model);
    }
    c.width = parseField<std::uint64_t>(in, lines, "WIDTH");
    c.height = parseField<std::uint64_t>(in, lines, "HEIGHT");
    std::string token;
    while (in >> token) {
      std::istringstream one(token);
      c.params.push_back(parseDouble(one, lines, "PARAMS"));
    }
    validateCamera(c, path, lines.where());
    cameras.push_back(c);
  }
  return cameras;
}

std::vector<ColmapImage> readImagesText(const std::string& path) {
  TextLines lines(path);
  std::vector<ColmapImage> images;
  std::string line;
  while (lines.nextContent(&line)) {
    std::istringstream in(line);
    ColmapImage im;
    im.id = parseField<std::uint32_t>(in, lines, "IMAGE_ID");
    for (int i = 0; i < 4; ++i) im.qvec[i] = parseDouble(in, lines, "QVEC");
    for (int i = 0; i < 3; ++i) im.tvec[i] = parseDouble(in, lines, "TVEC");
    im.camera_id = parseField<std::uint32_t>(in, lines, "CAMERA_ID");
    std::getline(in >> std::ws, im.name);
    while (!im.name.empty() && (im.name.back() == ' ' || im.name.back() == '\r'))
      im.name.pop_back();
    validateImage(im, path, lines.where());
    const std::string image_where = lines.where();
    std::string points_line;
    if (lines.nextRaw(&points_line)) {
      std::istringstream pin(points_line);
      std::string tx;
      while (pin >> tx) {
        ColmapPoint2D p;
        std::istringstream one(tx);
        p.x = parseDouble(one, lines, "POINTS2D x");
        p.y = parseDouble(pin, lines, "POINTS2D y");
        p.point3d_id = parseField<std::int64_t>(pin, lines, "POINTS2D POINT3D_ID");
        im.points2d.push_back(p);
      }
    }
    images.push_back(std::move(im));
  }
  return images;
}

std::vector<ColmapPoint3D> readPointsText(const std::string& path) {
  TextLines lines(path);
  std::vector<ColmapPoint3D> points;
  std::string line;
  while (lines.nextContent(&line)) {
    std::istringstream in(line);
    ColmapPoint3D p;
    p.id = parseField<std::uint64_t>(in, lines, "POINT3D_ID");
    for (int i = 0; i < 3; ++i) p.xyz[i] = parseDouble(in, lines, "XYZ");
    for (int i = 0; i < 3; ++i) {
      const int v = parseField<int>(in, lines, "RGB");
      if (v < 0 || v > 255) throw Error(path, lines.where() + " RGB", "0..255", std::to_string(v));
      p.rgb[i] = static_cast<std::uint8_t>(v);
    }
    p.error = parseDouble(in, lines, "ERROR");
    std::uint32_t image_id = 0;
    while (in >> image_id) {
      const auto idx = parseField<std::uint32_t>(in, lines, "TRACK point2D_idx");
      p.track.emplace_back(image_id, idx);
    }
    if (!in.eof()) {
      throw Error(path, lines.where() + " TRACK", "pairs of integers", "an odd count or a word");
    }
    points.push_back(std::move(p));
  }
  return points;
}

// ---- binary ----------------------------------------------------------------------------------

class BinaryReader {
 public:
  explicit BinaryReader(const std::string& path) : path_(path), bytes_(readWholeFile(path)) {}
  template <typename T>
  T read(const std::string& field) {
    if (pos_ + sizeof(T) > bytes_.size()) {
      throw Error(path_, field, "more data (file is truncated)", "end of file");
    }
    T v;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  double readFinite(const std::string& field) {
    const double v = read<double>(field);
    requireFinite(v, path_, field);
    return v;
  }
  std::string readCString(const std::string& field) {
    const auto end = bytes_.find('\0', pos_);
    if (end == std::string::npos) throw Error(path_, field, "a NUL-terminated name", "EOF");
    std::string s = bytes_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }
  // Guards counts read from the file against absurd values before allocating.
  void requireRemaining(std::uint64_t count, std::size_t min_item_bytes, const std::string& field) {
    if (count > (bytes_.size() - pos_) / std::max<std::size_t>(1, min_item_bytes)) {
      throw Error(path_, field, "a count that fits the file size (file is truncated?)",
                  std::to_string(count));
    }
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string bytes_;
  std::size_t pos_ = 0;
};

std::vector<ColmapCamera> readCamerasBinary(const std::string& path) {
  BinaryReader r(path);
  const auto n = r.read<std::uint64_t>("num_cameras");
  r.requireRemaining(n, 24, "num_cameras");
  std::vector<ColmapCamera> cameras(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    const std::string where = "camera record " + std::to_string(i);
    ColmapCamera& c = cameras[i];
    c.id = r.read<std::uint32_t>(where + " camera_id");
    const int model = r.read<std::int32_t>(where + " model_id");
    if (!knownModel(model)) {
      throw Error(path, where + " model_id",
                  "0..6 (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, "
                  "OPENCV_FISHEYE, FULL_OPENCV)",
                  std::to_string(model));
    }
    c.model = static_cast<CameraModel>(model);
    c.width = r.read<std::uint64_t>(where + " width");
    c.height = r.read<std::uint64_t>(where + " height");
    c.params.resize(cameraModelNumParams(c.model));
    for (double& p : c.params) p = r.readFinite(where + " params");
    validateCamera(c, path, where);
  }
  return cameras;
}

std::vector<ColmapImage> readImagesBinary(const std::string& path) {
  BinaryReader r(path);
  const auto n = r.read<std::uint64_t>("num_reg_images");
  r.requireRemaining(n, 64, "num_reg_images");
  std::vector<ColmapImage> images(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    const std::string where = "image record " + std::to_string(i);
    ColmapImage& im = images[i];
    im.id = r.read<std::uint32_t>(where + " image_id");
    for (double& q : im.qvec) q = r.readFinite(where + " qvec");
    for (double& t : im.tvec) t = r.readFinite(where + " tvec");
    im.camera_id = r.read<std::uint32_t>(where + " camera_id");
    im.name = r.readCString(where + " name");
    validateImage(im, path, where);
    const auto np = r.read<std::uint64_t>(where + " num_points2D");
    r.requireRemaining(np, 24, where + " num_points2D");
    im.points2d.resize(np);
    for (ColmapPoint2D& p : im.points2d) {
      p.x = r.read<double>(where + " points2D x");
      p.y = r.read<double>(where + " points2D y");
      const auto id = r.read<std::uint64_t>(where + " points2D point3D_id");
      p.point3d_id =
          id == std::numeric_limits<std::uint64_t>::max() ? -1 : static_cast<std::int64_t>(id);
    }
  }
  return images;
}

std::vector<ColmapPoint3D> readPointsBinary(const std::string& path) {
  BinaryReader r(path);
  const auto n = r.read<std::uint64_t>("num_points3D");
  r.requireRemaining(n, 43, "num_points3D");
  std::vector<ColmapPoint3D> points(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    const std::string where = "point3D record " + std::to_string(i);
    ColmapPoint3D& p = points[i];
    p.id = r.read<std::uint64_t>(where + " point3D_id");
    for (double& v : p.xyz) v = r.readFinite(where + " xyz");
    for (auto& c : p.rgb) c = r.read<std::uint8_t>(where + " rgb");
    p.error = r.read<double>(where + " error");
    const auto len = r.read<std::uint64_t>(where + " track_length");
    r.requireRemaining(len, 8, where + " track_length");
    p.track.resize(len);
    for (auto& t : p.track) {
      t.first = r.read<std::uint32_t>(where + " track image_id");
      t.second = r.read<std::uint32_t>(where + " track point2D_idx");
    }
  }
  return points;
}

void validateModel(const ColmapModel& model, const std::string& dir) {
  std::set<std::uint32_t> camera_ids;
  for (const auto& c : model.cameras) {
    if (!camera_ids.insert(c.id).second) {
      throw Error(dir + "/cameras", "CAMERA_ID " + std::to_string(c.id), "unique camera ids",
                  "a duplicate");
    }
  }
  std::set<std::uint32_t> image_ids;
  for (const auto& im : model.images) {
    if (!image_ids.insert(im.id).second) {
      throw Error(dir + "/images", "IMAGE_ID " + std::to_string(im.id), "unique image ids",
                  "a duplicate");
    }
    if (!camera_ids.count(im.camera_id)) {
      throw Error(dir + "/images", "image " + im.name + " CAMERA_ID",
                  "the id of a camera in cameras", std::to_string(im.camera_id));
    }
  }
}

template <typename T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

}  // namespace

const char* cameraModelName(CameraModel model) {
  switch (model) {
    case CameraModel::kSimplePinhole:
      return "SIMPLE_PINHOLE";
    case CameraModel::kPinhole:
      return "PINHOLE";
    case CameraModel::kSimpleRadial:
      return "SIMPLE_RADIAL";
    case CameraModel::kRadial:
      return "RADIAL";
    case CameraModel::kOpenCV:
      return "OPENCV";
    case CameraModel::kOpenCVFisheye:
      return "OPENCV_FISHEYE";
    case CameraModel::kFullOpenCV:
      return "FULL_OPENCV";
  }
  return "UNKNOWN";
}

int cameraModelNumParams(CameraModel model) {
  switch (model) {
    case CameraModel::kSimplePinhole:
      return 3;
    case CameraModel::kPinhole:
      return 4;
    case CameraModel::kSimpleRadial:
      return 4;
    case CameraModel::kRadial:
      return 5;
    case CameraModel::kOpenCV:
    case CameraModel::kOpenCVFisheye:
      return 8;
    case CameraModel::kFullOpenCV:
      return 12;
  }
  return 0;
}

bool cameraModelHasFy(CameraModel model) {
  return model == CameraModel::kPinhole || model == CameraModel::kOpenCV ||
         model == CameraModel::kOpenCVFisheye || model == CameraModel::kFullOpenCV;
}

ColmapModel readColmapModel(const std::string& dir) {
  ColmapModel model;
  const bool binary = isRegularFile(dir + "/cameras.bin") && isRegularFile(dir + "/images.bin") &&
                      isRegularFile(dir + "/points3D.bin");
  if (binary) {
    model.cameras = readCamerasBinary(dir + "/cameras.bin");
    model.images = readImagesBinary(dir + "/images.bin");
    model.points = readPointsBinary(dir + "/points3D.bin");
  } else {
    for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
      if (!isRegularFile(dir + "/" + name)) {
        throw Error(dir + "/" + name, "file",
                    "a COLMAP model: cameras, images and points3D as .txt or .bin", "missing");
      }
    }
    model.cameras = readCamerasText(dir + "/cameras.txt");
    model.images = readImagesText(dir + "/images.txt");
    model.points = readPointsText(dir + "/points3D.txt");
  }
  validateModel(model, dir);
  return model;
}

void writeColmapText(const std::string& dir, const ColmapModel& model) {
  std::ostringstream cams;
  cams << std::setprecision(17);
  cams << "# Camera list with one line of data per camera:\n"
       << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
       << "# Number of cameras: " << model.cameras.size() << "\n";
  for (const auto& c : model.cameras) {
    cams << c.id << " " << cameraModelName(c.model) << " " << c.width << " " << c.height;
    for (double p : c.params) cams << " " << p;
    cams << "\n";
  }
  writeTextFileAtomically(dir + "/cameras.txt", cams.str());

  std::ostringstream ims;
  ims << std::setprecision(17);
  ims << "# Image list with two lines of data per image:\n"
      << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      << "# Number of images: " << model.images.size() << "\n";
  for (const auto& im : model.images) {
    ims << im.id;
    for (double q : im.qvec) ims << " " << q;
    for (double t : im.tvec) ims << " " << t;
    ims << " " << im.camera_id << " " << im.name << "\n";
    for (std::size_t i = 0; i < im.points2d.size(); ++i) {
      const auto& p = im.points2d[i];
      ims << (i ? " " : "") << p.x << " " << p.y << " " << p.point3d_id;
    }
    ims << "\n";
  }
  writeTextFileAtomically(dir + "/images.txt", ims.str());

  std::ostringstream pts;
  pts << std::setprecision(17);
  pts << "# 3D point list with one line of data per point:\n"
      << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      << "# Number of points: " << model.points.size() << "\n";
  for (const auto& p : model.points) {
    pts << p.id << " " << p.xyz[0] << " " << p.xyz[1] << " " << p.xyz[2] << " " << int(p.rgb[0])
        << " " << int(p.rgb[1]) << " " << int(p.rgb[2]) << " " << p.error;
    for (const auto& t : p.track) pts << " " << t.first << " " << t.second;
    pts << "\n";
  }
  writeTextFileAtomically(dir + "/points3D.txt", pts.str());
}

void writeColmapBinary(const std::string& dir, const ColmapModel& model) {
  std::string cams;
  put<std::uint64_t>(cams, model.cameras.size());
  for (const auto& c : model.cameras) {
    put<std::uint32_t>(cams, c.id);
    put<std::int32_t>(cams, static_cast<std::int32_t>(c.model));
    put<std::uint64_t>(cams, c.width);
    put<std::uint64_t>(cams, c.height);
    for (double p : c.params) put<double>(cams, p);
  }
  writeTextFileAtomically(dir + "/cameras.bin", cams);

  std::string ims;
  put<std::uint64_t>(ims, model.images.size());
  for (const auto& im : model.images) {
    put<std::uint32_t>(ims, im.id);
    for (double q : im.qvec) put<double>(ims, q);
    for (double t : im.tvec) put<double>(ims, t);
    put<std::uint32_t>(ims, im.camera_id);
    ims.append(im.name);
    ims.push_back('\0');
    put<std::uint64_t>(ims, im.points2d.size());
    for (const auto& p : im.points2d) {
      put<double>(ims, p.x);
      put<double>(ims, p.y);
      put<std::uint64_t>(ims, p.point3d_id < 0 ? std::numeric_limits<std::uint64_t>::max()
                                               : static_cast<std::uint64_t>(p.point3d_id));
    }
  }
  writeTextFileAtomically(dir + "/images.bin", ims);

  std::string pts;
  put<std::uint64_t>(pts, model.points.size());
  for (const auto& p : model.points) {
    put<std::uint64_t>(pts, p.id);
    for (double v : p.xyz) put<double>(pts, v);
    for (auto c : p.rgb) put<std::uint8_t>(pts, c);
    put<double>(pts, p.error);
    put<std::uint64_t>(pts, p.track.size());
    for (const auto& t : p.track) {
      put<std::uint32_t>(pts, t.first);
      put<std::uint32_t>(pts, t.second);
    }
  }
  writeTextFileAtomically(dir + "/points3D.bin", pts);
}

}  // namespace io
}  // namespace sadsplat
