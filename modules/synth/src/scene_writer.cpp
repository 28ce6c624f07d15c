#include "sadsplat/synth/scene_writer.h"

#include <iomanip>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstring>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace synth {
namespace {

void writePng(const std::string& path, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  if (!cv::imencode(".png", image, bytes))
    throw Error(path, "PNG encoding", "success", "a failure of OpenCV's encoder");
  io::writeFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  });
}

// NumPy .npy (version 1.0) of a float32 H x W array.
void writeNpy(const std::string& path, const std::vector<float>& data, int height, int width) {
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                       std::to_string(height) + ", " + std::to_string(width) + "), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  io::writeFileAtomically(path, [&](std::ostream& out) {
    out.write("\x93NUMPY\x01\x00", 8);
    const std::uint16_t len = static_cast<std::uint16_t>(header.size());
    out.write(reinterpret_cast<const char*>(&len), 2);
    out << header;
    out.write(reinterpret_cast<const char*>(data.data()),
              static_cast<std::streamsize>(data.size() * 4));
  });
}

cv::Mat colorLabels(const SynthView& v, const std::vector<ClassInfo>& classes) {
  cv::Mat out(v.labels.height, v.labels.width, CV_8UC3);
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      const std::uint8_t l = v.labels.at(x, y);
      cv::Vec3b& px = out.at<cv::Vec3b>(y, x);
      if (l == io::kIgnoreLabel) {
        px = {0, 0, 0};
      } else {
        px = {classes[l].color[2], classes[l].color[1], classes[l].color[0]};
      }
    }
  }
  return out;
}

cv::Mat bgr(const SynthView& v) {
  cv::Mat rgb(v.rgb.height, v.rgb.width, CV_8UC3, const_cast<std::uint8_t*>(v.rgb.pixels.data()));
  cv::Mat out;
  cv::cvtColor(rgb, out, cv::COLOR_RGB2BGR);
  return out;
}

}  // namespace

void writeScene(const SynthScene& scene, const std::string& dir, ColmapFormat colmap) {
  io::makeDirectory(dir);
  for (const char* sub : {"/images", "/labels", "/depth", "/sparse", "/sparse/0"})
    io::makeDirectory(dir + sub);
  io::ColmapModel model;
  io::ColmapCamera cam;
  cam.id = 1;
  cam.model = io::CameraModel::kPinhole;
  const auto& c0 = scene.views.front().camera;
  cam.width = static_cast<std::uint64_t>(c0.width);
  cam.height = static_cast<std::uint64_t>(c0.height);
  cam.params = {c0.fx, c0.fy, c0.cx, c0.cy};
  model.cameras.push_back(cam);
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const SynthView& v = scene.views[i];
    writePng(dir + "/images/" + v.name, bgr(v));
    cv::Mat labels(v.labels.height, v.labels.width, CV_8UC1,
                   const_cast<std::uint8_t*>(v.labels.pixels.data()));
    writePng(dir + "/labels/" + v.name, labels);
    writeNpy(dir + "/depth/" + v.name.substr(0, v.name.size() - 4) + ".npy", v.depth, v.rgb.height,
             v.rgb.width);
    io::ColmapImage im;
    im.id = static_cast<std::uint32_t>(i + 1);
    im.qvec = v.camera.qvec;
    im.tvec = v.camera.tvec;
    im.camera_id = 1;
    im.name = v.name;
    model.images.push_back(im);
  }
  for (std::size_t k = 0; k < scene.points.size(); ++k) {
    const SynthPoint& p = scene.points[k];
    io::ColmapPoint3D out;
    out.id = k + 1;
    for (int a = 0; a < 3; ++a) out.xyz[a] = p.xyz[a];
    for (int a = 0; a < 3; ++a) out.rgb[a] = p.rgb[a];
    out.error = 0.5;
    for (const auto& [view, uv] : p.track) {
      auto& points2d = model.images[view].points2d;
      out.track.emplace_back(static_cast<std::uint32_t>(view + 1),
                             static_cast<std::uint32_t>(points2d.size()));
      points2d.push_back({uv[0], uv[1], static_cast<std::int64_t>(k + 1)});
    }
    model.points.push_back(std::move(out));
  }
  if (colmap == ColmapFormat::kBinary) {
    io::writeColmapBinary(dir + "/sparse/0", model);
  } else {
    io::writeColmapText(dir + "/sparse/0", model);
  }
  io::writeClassesJson(dir + "/classes.json", scene.classes);
  io::writeSplitJson(dir + "/split.json", scene.split);
  if (!scene.ortho.classes.empty()) {
    const OrthoTruth& t = scene.ortho;
    cv::Mat truth(t.height, t.width, CV_8UC1, const_cast<std::uint8_t*>(t.classes.data()));
    writePng(dir + "/ortho_truth.png", truth);
    std::ostringstream json;
    json
        << std::setprecision(17)
        << "{\n  \"frame\": \"scene (metres, z up)\",\n  \"gsd\": " << t.gsd
        << ",\n  \"x0\": " << t.x0 << ",\n  \"y0\": " << t.y0 << ",\n  \"width\": " << t.width
        << ",\n  \"height\": " << t.height
        << ",\n  \"classes_png\": \"ortho_truth.png\",\n  \"world\": \"" << scene.world
        << "\",\n  \"note\": \"class of the topmost surface "
           "at each cell centre, 255 = outside the labelled area\"\n}\n";
    io::writeFileAtomically(dir + "/ortho_truth.json",
                            [&](std::ostream& out) { out << json.str(); });
  }
}

void writeContactSheet(const SynthScene& scene, const std::string& png_path) {
  const int V = static_cast<int>(scene.views.size());
  const int picks[4] = {0, V / 4, V / 2, (3 * V) / 4};
  const int panel_w = std::min(480, scene.views[0].rgb.width);
  const int panel_h = panel_w * scene.views[0].rgb.height / scene.views[0].rgb.width;
  cv::Mat sheet(4 * panel_h, 2 * panel_w, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int r = 0; r < 4; ++r) {
    const SynthView& v = scene.views[picks[r]];
    cv::Mat a, b;
    cv::resize(bgr(v), a, cv::Size(panel_w, panel_h), 0, 0, cv::INTER_AREA);
    cv::resize(colorLabels(v, scene.classes), b, cv::Size(panel_w, panel_h), 0, 0,
               cv::INTER_NEAREST);
    a.copyTo(sheet(cv::Rect(0, r * panel_h, panel_w, panel_h)));
    b.copyTo(sheet(cv::Rect(panel_w, r * panel_h, panel_w, panel_h)));
  }
  writePng(png_path, sheet);
}

}  // namespace synth
}  // namespace sadsplat
