#include "sadsplat/io/scene_import.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/io/annotations.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/image_file.h"
#include "sadsplat/io/transforms_json.h"

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core/types.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace sadsplat {
namespace io {

bool haveSceneImport() { return SADSPLAT_HAVE_OPENCV != 0; }

namespace {

std::string colmapModelIn(const std::string& dir) {
  // COLMAP's mapper writes sparse/0, 1, ...; its image_undistorter writes sparse/ itself.
  for (const std::string sub : {"/sparse/0", "/sparse"}) {
    for (const char* file : {"/cameras.bin", "/cameras.txt"}) {
      if (pathExists(dir + sub + file)) return dir + sub;
    }
  }
  return "";
}

}  // namespace

std::string findColmapModel(const std::string& dir) {
  const std::string found = colmapModelIn(dir);
  if (!found.empty()) return found;
  throw Error(dir + "/sparse", "COLMAP model",
              "cameras, images and points3D (.bin or .txt) in sparse/0/ (COLMAP's mapper) or "
              "sparse/ (its image_undistorter), or a transforms.json (nerfstudio, instant-ngp); "
              "`sadsplat sfm PHOTOS --out SCENE` makes one",
              pathExists(dir + "/sparse") ? "no cameras.bin or cameras.txt there" : "missing");
}

PosedImages readPosedImages(const std::string& dir, const ImageSizeOf& image_size) {
  PosedImages posed;
  const std::string colmap = colmapModelIn(dir);
  if (colmap.empty() && isRegularFile(dir + "/transforms.json")) {
    TransformsJson t = readTransformsJson(dir + "/transforms.json", image_size);
    posed.model = std::move(t.model);
    posed.image_dir = std::move(t.image_dir);
    posed.mask_paths = std::move(t.mask_paths);
    posed.origin = dir + "/transforms.json";
    return posed;
  }
  posed.origin = findColmapModel(dir);
  posed.model = readColmapModel(posed.origin);
  posed.image_dir = dir + "/images";
  return posed;
}

SplitInfo defaultSplit(const ColmapModel& model, int test_every) {
  std::vector<std::string> names;
  for (const auto& im : model.images) names.push_back(im.name);
  std::sort(names.begin(), names.end());
  SplitInfo split;
  for (std::size_t i = 0; i < names.size(); ++i) {
    // Every test_every-th view (0, N, 2N, ...) is held out, as in Mip-NeRF 360's evaluation;
    // a scene of fewer than 2 * test_every views keeps every view for training.
    const bool test = test_every > 0 && names.size() >= 2 * static_cast<std::size_t>(test_every) &&
                      i % test_every == 0;
    (test ? split.test : split.train).push_back(names[i]);
  }
  return split;
}

#if !SADSPLAT_HAVE_OPENCV
Scene importScene(const std::string& dir, const ImportOptions&) {
  throw Error(dir, "scene import", "a sadsplat build with OpenCV (SADSPLAT_WITH_OPENCV=ON)",
              "a build without it; import the scene elsewhere and use its scene cache");
}
#else
namespace {

std::string stem(const std::string& name) {
  const auto slash = name.find_last_of('/');
  const std::string base = slash == std::string::npos ? name : name.substr(slash + 1);
  const auto dot = base.find_last_of('.');
  const std::string dir = slash == std::string::npos ? "" : name.substr(0, slash + 1);
  return dir + (dot == std::string::npos ? base : base.substr(0, dot));
}

Image8 toImage8(const cv::Mat& mat) {
  Image8 image;
  image.width = mat.cols;
  image.height = mat.rows;
  image.channels = mat.channels();
  const cv::Mat contiguous = mat.isContinuous() ? mat : mat.clone();
  image.pixels.assign(contiguous.data,
                      contiguous.data + contiguous.total() * contiguous.elemSize());
  return image;
}

// Camera matrix and distortion in OpenCV's convention (pixel centres at integers, hence -0.5).
void opencvIntrinsics(const ColmapCamera& c, cv::Mat* K, cv::Mat* dist, PinholeCamera* pinhole) {
  const auto& p = c.params;
  double fx = p[0], fy = p[0], cx = p[1], cy = p[2];
  std::vector<double> d(4, 0.0);
  switch (c.model) {
    case CameraModel::kSimplePinhole:
      break;
    case CameraModel::kPinhole:
      fy = p[1];
      cx = p[2];
      cy = p[3];
      break;
    case CameraModel::kSimpleRadial:
      d[0] = p[3];
      break;
    case CameraModel::kRadial:
      d[0] = p[3];
      d[1] = p[4];
      break;
    case CameraModel::kOpenCV:
    case CameraModel::kOpenCVFisheye:  // k1..k4 of cv::fisheye
      fy = p[1];
      cx = p[2];
      cy = p[3];
      d = {p[4], p[5], p[6], p[7]};
      break;
    case CameraModel::kFullOpenCV:  // OpenCV's rational model: k1 k2 p1 p2 k3 k4 k5 k6
      fy = p[1];
      cx = p[2];
      cy = p[3];
      d.assign(p.begin() + 4, p.end());
      break;
  }
  *K = (cv::Mat_<double>(3, 3) << fx, 0, cx - 0.5, 0, fy, cy - 0.5, 0, 0, 1);
  *dist = cv::Mat(d, true).reshape(1, 1);
  pinhole->fx = fx;
  pinhole->fy = fy;
  pinhole->cx = cx;
  pinhole->cy = cy;
}

bool isDistorted(const ColmapCamera& c) {
  return c.model != CameraModel::kSimplePinhole && c.model != CameraModel::kPinhole;
}

// Maps from the undistorted pinhole image (same K, same size) into the distorted photo.
void undistortionMaps(const ColmapCamera& c, const cv::Mat& K, const cv::Mat& dist,
                      const cv::Size& size, cv::Mat* map1, cv::Mat* map2) {
  if (c.model == CameraModel::kOpenCVFisheye) {
    cv::fisheye::initUndistortRectifyMap(K, dist, cv::Mat::eye(3, 3, CV_64F), K, size, CV_32FC1,
                                         *map1, *map2);
  } else {
    cv::initUndistortRectifyMap(K, dist, cv::Mat(), K, size, CV_32FC1, *map1, *map2);
  }
}

// A view's mask: transforms.json's mask_path, else masks/<name>.png, else masks/<stem>.png.
std::string userMaskPath(const std::string& dir, const PosedImages& posed,
                         const std::string& name) {
  const auto given = posed.mask_paths.find(name);
  if (given != posed.mask_paths.end()) return given->second;
  for (const std::string& candidate :
       {dir + "/masks/" + name + ".png", dir + "/masks/" + stem(name) + ".png"}) {
    if (optionalFileExists(candidate)) return candidate;
  }
  return "";
}

// A mask as users draw them (nerfstudio, COLMAP, OpenDroneMap): 0 = leave out, else keep; any
// channel count (a colour mask keeps a pixel where any channel is non-zero).
cv::Mat readUserMask(const std::string& path, const cv::Size& size) {
  const cv::Mat raw =
      decodeImage(path, cv::IMREAD_UNCHANGED | cv::IMREAD_IGNORE_ORIENTATION, "mask (PNG)");
  if (raw.depth() != CV_8U) {
    throw Error(path, "pixel depth", "an 8-bit mask", "depth code " + std::to_string(raw.depth()));
  }
  if (raw.size() != size) {
    throw Error(path, "size",
                std::to_string(size.width) + "x" + std::to_string(size.height) + " (its image)",
                std::to_string(raw.cols) + "x" + std::to_string(raw.rows));
  }
  cv::Mat keep(raw.size(), CV_8UC1, cv::Scalar(0));
  // Grey (+ alpha): the grey; colour (+ alpha): any colour channel. Alpha is not the mask.
  const int channels = raw.channels() >= 3 ? 3 : 1;
  for (int y = 0; y < raw.rows; ++y) {
    const std::uint8_t* px = raw.ptr<std::uint8_t>(y);
    auto* out = keep.ptr<std::uint8_t>(y);
    for (int x = 0; x < raw.cols; ++x) {
      bool any = false;
      for (int c = 0; c < channels; ++c) any |= px[x * raw.channels() + c] != 0;
      out[x] = any ? 255 : 0;
    }
  }
  return keep;
}

cv::Mat readLabelMap(const std::string& path, const std::vector<ClassInfo>& classes) {
  ImageHeader header;
  cv::Mat raw = decodeImage(path, cv::IMREAD_UNCHANGED, "PNG label map", &header);
  if (raw.depth() != CV_8U) {
    throw Error(path, "pixel depth", "8-bit label map",
                "depth code " + std::to_string(raw.depth()));
  }
  cv::Mat labels(raw.rows, raw.cols, CV_8UC1);
  // A grey PNG with an alpha channel (colour type 4) or a transparent grey (tRNS) is decoded as
  // BGRA with B = G = R = the grey: its grey is the class id, a fully transparent pixel ignore.
  const bool grey_png = header.png_colour_type == 0 || header.png_colour_type == 4;
  if (grey_png && raw.channels() == 4) {
    cv::Mat ids(raw.rows, raw.cols, CV_8UC1);
    for (int y = 0; y < raw.rows; ++y) {
      const std::uint8_t* px = raw.ptr<std::uint8_t>(y);
      auto* out = ids.ptr<std::uint8_t>(y);
      for (int x = 0; x < raw.cols; ++x) out[x] = px[4 * x + 3] == 0 ? kIgnoreLabel : px[4 * x];
    }
    raw = ids;
  }
  if (raw.channels() == 1) {
    labels = raw;
    for (int y = 0; y < labels.rows; ++y) {
      const auto* row = labels.ptr<std::uint8_t>(y);
      for (int x = 0; x < labels.cols; ++x) {
        if (row[x] != kIgnoreLabel && row[x] >= classes.size()) {
          throw Error(path, "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")",
                      "a class id below " + std::to_string(classes.size()) + " or 255 (ignore)",
                      std::to_string(row[x]));
        }
      }
    }
    return labels;
  }
  if (raw.channels() != 3 && raw.channels() != 4) {
    throw Error(path, "channels", "1 (class ids) or 3 (class colours)",
                std::to_string(raw.channels()));
  }
  std::map<std::uint32_t, std::uint8_t> palette;
  auto key = [](int r, int g, int b) { return std::uint32_t(r) << 16 | std::uint32_t(g) << 8 | b; };
  palette[key(0, 0, 0)] = kIgnoreLabel;
  for (std::size_t i = 0; i < classes.size(); ++i) {
    palette[key(classes[i].color[0], classes[i].color[1], classes[i].color[2])] =
        static_cast<std::uint8_t>(i);
  }
  for (int y = 0; y < raw.rows; ++y) {
    for (int x = 0; x < raw.cols; ++x) {
      const std::uint8_t* px = raw.ptr<std::uint8_t>(y) + x * raw.channels();  // BGR(A)
      const auto it = palette.find(key(px[2], px[1], px[0]));
      if (it == palette.end()) {
        throw Error(path, "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")",
                    "a colour from classes.json or black (ignore)",
                    "(" + std::to_string(px[2]) + ", " + std::to_string(px[1]) + ", " +
                        std::to_string(px[0]) + ")");
      }
      labels.at<std::uint8_t>(y, x) = it->second;
    }
  }
  return labels;
}

// Sutherland-Hodgman: the polygon clipped to the box [x0, x1] x [y0, y1] (exact inside it).
std::vector<std::array<double, 2>> clipToBox(std::vector<std::array<double, 2>> polygon, double x0,
                                             double y0, double x1, double y1) {
  for (int edge = 0; edge < 4; ++edge) {
    const int axis = edge % 2;  // 0: x, 1: y
    const double bound = edge == 0 ? x0 : edge == 1 ? y0 : edge == 2 ? x1 : y1;
    const bool keep_above = edge < 2;
    const auto inside = [&](const std::array<double, 2>& p) {
      return keep_above ? p[axis] >= bound : p[axis] <= bound;
    };
    std::vector<std::array<double, 2>> out;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const auto& a = polygon[i];
      const auto& b = polygon[(i + 1) % polygon.size()];
      if (inside(a)) out.push_back(a);
      if (inside(a) != inside(b)) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        std::array<double, 2> c = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
        c[axis] = bound;
        out.push_back(c);
      }
    }
    polygon = std::move(out);
  }
  return polygon;
}

// The label map of an annotated image at the scene image's size (before undistortion).
cv::Mat rasterise(const AnnotatedImage& a, const cv::Size& size,
                  const std::map<std::string, std::uint8_t>& class_ids, const std::string& origin) {
  const double sx = static_cast<double>(size.width) / a.width;
  const double sy = static_cast<double>(size.height) / a.height;
  if (std::abs(sx / sy - 1) > 0.02) {
    throw Error(origin, "image " + a.file_name + " size",
                "the aspect ratio of the scene's image " + std::to_string(size.width) + "x" +
                    std::to_string(size.height),
                std::to_string(a.width) + "x" + std::to_string(a.height));
  }
  cv::Mat labels(size, CV_8UC1, cv::Scalar(kIgnoreLabel));
  constexpr int kShift = 4;  // sub-pixel polygon vertices: 1/16 pixel
  for (const AnnotatedShape& shape : a.shapes) {
    const std::uint8_t id = class_ids.at(shape.label);
    if (!shape.mask.empty()) {
      cv::Mat mask(a.height, a.width, CV_8UC1, const_cast<std::uint8_t*>(shape.mask.data()));
      cv::Mat scaled;
      cv::resize(mask, scaled, size, 0, 0, cv::INTER_NEAREST);
      labels.setTo(cv::Scalar(id), scaled);
      continue;
    }
    std::vector<std::vector<cv::Point> > rings;
    for (const auto& polygon : shape.polygons) {
      std::vector<std::array<double, 2>> scaled;
      // Annotation coordinates: pixel centres at +0.5, as sadsplat's cameras.
      for (const auto& p : polygon) scaled.push_back({p[0] * sx - 0.5, p[1] * sy - 0.5});
      // Clipped to just outside the image first: a rectangle drawn far beyond the photo still
      // covers it, and no vertex overflows OpenCV's fixed-point int coordinates.
      scaled = clipToBox(scaled, -2.0, -2.0, size.width + 1.0, size.height + 1.0);
      std::vector<cv::Point> ring;
      for (const auto& p : scaled) {
        ring.emplace_back(static_cast<int>(std::lround(p[0] * (1 << kShift))),
                          static_cast<int>(std::lround(p[1] * (1 << kShift))));
      }
      if (ring.size() >= 3) rings.push_back(std::move(ring));
    }
    cv::fillPoly(labels, rings, cv::Scalar(id), cv::LINE_8, kShift);
  }
  return labels;
}

}  // namespace

Scene importScene(const std::string& dir, const ImportOptions& options) {
  // OpenCV's own warnings (a damaged PNG) would precede sadsplat's one-line error.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  if (!(options.scale > 0.0 && options.scale <= 1.0)) {
    throw Error("<import options>", "scale", "a value in (0, 1]", std::to_string(options.scale));
  }
  if (!pathExists(dir)) throw Error(dir, "scene directory", "an existing directory", "missing");
  Scene scene;
  scene.source = dir;
  // Without classes.json the scene trains as plain 3DGS (no semantic head).
  if (optionalFileExists(dir + "/classes.json")) {
    scene.classes = readClassesJson(dir + "/classes.json");
  }
  const PosedImages posed = readPosedImages(dir, [](const std::string& image_path) {
    // The header's size when the format is known (no decoding), else the decoded image's.
    const ImageHeader header = checkImageBudget(image_path, "image");
    if (!header.format.empty()) {
      return std::array<int, 2>{static_cast<int>(header.width), static_cast<int>(header.height)};
    }
    const cv::Mat image =
        decodeImage(image_path, cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION, "image");
    return std::array<int, 2>{image.cols, image.rows};
  });
  const ColmapModel& model = posed.model;
  std::map<std::uint32_t, const ColmapCamera*> cameras;
  for (const auto& c : model.cameras) cameras[c.id] = &c;

  SplitInfo split;
  const bool have_split = optionalFileExists(dir + "/split.json");
  if (have_split) {
    split = readSplitJson(dir + "/split.json");
  } else {
    split = defaultSplit(model, options.test_every);
  }
  const std::set<std::string> train(split.train.begin(), split.train.end());
  const std::set<std::string> test(split.test.begin(), split.test.end());
  const std::set<std::string> labelled(split.labelled.begin(), split.labelled.end());
  std::set<std::string> image_names;
  for (const auto& im : model.images) image_names.insert(im.name);
  for (const auto* list : {&split.train, &split.test}) {
    for (const auto& name : *list) {
      if (!image_names.count(name)) {
        throw Error(dir + "/split.json", "image " + name, "an image of " + posed.origin, "unknown");
      }
    }
  }

  // Annotations from a labelling tool, by image file name.
  std::map<std::string, AnnotatedImage> annotated;
  if (!options.annotations.empty()) {
    if (scene.classes.empty()) {
      throw Error(dir + "/classes.json", "file", "the class list the annotations' labels name",
                  "missing");
    }
    std::map<std::string, std::string> view_of;  // file name -> image name in the model
    for (const auto& im : model.images) {
      view_of[im.name.substr(im.name.find_last_of('/') + 1)] = im.name;
    }
    for (AnnotatedImage& a : readAnnotations(options.annotations)) {
      const auto v = view_of.find(a.file_name);
      if (v == view_of.end()) {
        throw Error(options.annotations, "image " + a.file_name, "a photo of the scene",
                    "no view of that name");
      }
      for (const AnnotatedShape& shape : a.shapes) {
        const bool known = std::any_of(scene.classes.begin(), scene.classes.end(),
                                       [&](const ClassInfo& c) { return c.name == shape.label; });
        if (!known) {
          throw Error(options.annotations, "label \"" + shape.label + "\" of " + a.file_name,
                      "a class name from classes.json", "unknown");
        }
      }
      annotated[v->second] = std::move(a);
    }
  }
  std::map<std::string, std::uint8_t> class_ids;
  for (std::size_t i = 0; i < scene.classes.size(); ++i) {
    class_ids[scene.classes[i].name] = static_cast<std::uint8_t>(i);
  }

  std::vector<const ColmapImage*> images;
  for (const auto& im : model.images) images.push_back(&im);
  std::sort(images.begin(), images.end(),
            [](const ColmapImage* a, const ColmapImage* b) { return a->name < b->name; });

  for (const ColmapImage* im : images) {
    const ColmapCamera& cam = *cameras.at(im->camera_id);
    const std::string image_path = posed.image_dir + "/" + im->name;
    if (!pathExists(image_path)) {
      throw Error(image_path, "image data", "a readable image named in " + posed.origin, "missing");
    }
    // The header's size is checked against the camera before anything is decoded.
    const ImageHeader header = checkImageBudget(image_path, "image named in " + posed.origin);
    if (!header.format.empty() && (header.width != cam.width || header.height != cam.height)) {
      throw Error(image_path, "size",
                  std::to_string(cam.width) + "x" + std::to_string(cam.height) + " (camera " +
                      std::to_string(cam.id) + ")",
                  std::to_string(header.width) + "x" + std::to_string(header.height));
    }
    // Pixels as stored, as COLMAP and nerfstudio read them: their cameras describe those pixels
    // (an EXIF orientation tag is not applied; `sadsplat sfm` makes upright copies first).
    cv::Mat bgr = decodeImage(image_path, cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION,
                              "image named in " + posed.origin);
    if (bgr.cols != static_cast<int>(cam.width) || bgr.rows != static_cast<int>(cam.height)) {
      throw Error(image_path, "size",
                  std::to_string(cam.width) + "x" + std::to_string(cam.height) + " (camera " +
                      std::to_string(cam.id) + ")",
                  std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows));
    }
    View view;
    view.name = im->name;
    view.camera.qvec = im->qvec;
    view.camera.tvec = im->tvec;
    view.train = train.count(im->name) > 0;
    view.test = test.count(im->name) > 0;

    cv::Mat labels;
    const std::string label_path = dir + "/labels/" + stem(im->name) + ".png";
    const auto annotation = annotated.find(im->name);
    if (annotation != annotated.end()) {
      if (optionalFileExists(label_path)) {
        throw Error(options.annotations, "image " + annotation->second.file_name,
                    "one source of labels per view", "an annotation and " + label_path);
      }
      labels = rasterise(annotation->second, bgr.size(), class_ids, options.annotations);
    } else if (optionalFileExists(label_path)) {
      labels = readLabelMap(label_path, scene.classes);
      if (labels.size() != bgr.size()) {
        throw Error(label_path, "size",
                    std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) + " (its image)",
                    std::to_string(labels.cols) + "x" + std::to_string(labels.rows));
      }
    }
    view.labelled = have_split ? labelled.count(im->name) > 0 : (!labels.empty() && view.train);
    if (!labels.empty() && scene.classes.empty()) {
      throw Error(dir + "/classes.json", "file", "the class list the label maps in labels/ use",
                  "missing");
    }
    if (view.labelled && labels.empty()) {
      throw Error(label_path, "file", "a label map for labelled view " + im->name, "missing");
    }

    cv::Mat mask(bgr.size(), CV_8UC1, cv::Scalar(255));
    const std::string mask_path = userMaskPath(dir, posed, im->name);
    if (!mask_path.empty()) {
      const cv::Mat keep = readUserMask(mask_path, bgr.size());
      mask.setTo(0, keep == 0);
      if (!labels.empty()) labels.setTo(kIgnoreLabel, keep == 0);
    }
    cv::Mat K, dist;
    opencvIntrinsics(cam, &K, &dist, &view.camera);
    if (isDistorted(cam)) {
      cv::Mat map1, map2;
      undistortionMaps(cam, K, dist, bgr.size(), &map1, &map2);
      cv::Mat undistorted;
      cv::remap(bgr, undistorted, map1, map2, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
      bgr = undistorted;
      cv::Mat warped_mask;
      cv::remap(mask, warped_mask, map1, map2, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                cv::Scalar(0));
      mask = warped_mask;
      if (!labels.empty()) {
        cv::Mat warped;
        cv::remap(labels, warped, map1, map2, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                  cv::Scalar(kIgnoreLabel));
        labels = warped;
      }
    }

    double scale = options.scale;
    if (options.max_width > 0 && bgr.cols * scale > options.max_width) {
      scale = static_cast<double>(options.max_width) / bgr.cols;
    }
    const int w = std::max(1, static_cast<int>(std::lround(bgr.cols * scale)));
    const int h = std::max(1, static_cast<int>(std::lround(bgr.rows * scale)));
    if (w != bgr.cols || h != bgr.rows) {
      const double sx = static_cast<double>(w) / bgr.cols;
      const double sy = static_cast<double>(h) / bgr.rows;
      cv::Mat resized;
      cv::resize(bgr, resized, cv::Size(w, h), 0, 0, cv::INTER_AREA);
      bgr = resized;
      cv::resize(mask, resized, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
      mask = resized.clone();
      if (!labels.empty()) {
        cv::resize(labels, resized, cv::Size(w, h), 0, 0, cv::INTER_NEAREST);
        labels = resized.clone();
      }
      view.camera.fx *= sx;
      view.camera.cx *= sx;
      view.camera.fy *= sy;
      view.camera.cy *= sy;
    }
    view.camera.width = w;
    view.camera.height = h;
    view.camera.validate(posed.origin, "image " + im->name + " camera");
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    view.rgb = toImage8(rgb);
    view.mask = toImage8(mask);
    if (!labels.empty()) view.labels = toImage8(labels);
    scene.views.push_back(std::move(view));
  }

  if (optionalFileExists(dir + "/georeference.json")) {
    scene.georeference =
        georeferenceFromJson(readWholeFile(dir + "/georeference.json"), dir + "/georeference.json");
  }
  scene.points.reserve(model.points.size());
  for (const auto& p : model.points) {
    ScenePoint sp;
    for (int k = 0; k < 3; ++k) sp.xyz[k] = static_cast<float>(p.xyz[k]);
    sp.rgb = p.rgb;
    scene.points.push_back(sp);
  }
  return scene;
}
#endif

}  // namespace io
}  // namespace sadsplat
