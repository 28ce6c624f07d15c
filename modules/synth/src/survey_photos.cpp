#include "sadsplat/synth/survey_photos.h"
#include "sadsplat/geo/geodesy.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <random>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace synth {
namespace {

struct PhotoPose {
  double R[9];
  double t[3];
  double centre[3];
};

PhotoPose photoPoseOf(const io::PinholeCamera& c) {
  PhotoPose p;
  const double w = c.qvec[0], x = c.qvec[1], y = c.qvec[2], z = c.qvec[3];
  const double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                       2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                       2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
  for (int k = 0; k < 9; ++k) p.R[k] = R[k];
  for (int k = 0; k < 3; ++k) p.t[k] = c.tvec[k];
  for (int k = 0; k < 3; ++k) {
    p.centre[k] = -(R[k] * c.tvec[0] + R[3 + k] * c.tvec[1] + R[6 + k] * c.tvec[2]);
  }
  return p;
}

std::string photoStem(const std::string& name) { return name.substr(0, name.find_last_of('.')); }

}  // namespace

int writeSurveyPhotos(const SynthScene& scene, const SurveyPhotoOptions& o,
                      const std::string& dir) {
  io::makeDirectory(dir);
  std::mt19937 rng(static_cast<std::uint32_t>(o.seed));
  std::normal_distribution<double> normal(0, 1);
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const SynthView& v = scene.views[i];
    const PhotoPose p = photoPoseOf(v.camera);
    const std::array<double, 3> gps = {p.centre[0] + o.horizontal_noise * normal(rng),
                                       p.centre[1] + o.horizontal_noise * normal(rng),
                                       p.centre[2] + o.altitude_offset +
                                           o.altitude_wander * std::sin(0.3 * i) +
                                           o.altitude_noise * normal(rng)};
    cv::Mat rgb(v.rgb.height, v.rgb.width, CV_8UC3, const_cast<std::uint8_t*>(v.rgb.pixels.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    std::vector<unsigned char> jpeg;
    cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
    // The 35 mm equivalent focal length as COLMAP reads it (35 mm across the longest side).
    const int focal_35mm = static_cast<int>(
        std::lround(35.0 * v.camera.fx / std::max(v.camera.width, v.camera.height)));
    const auto bytes = io::jpegWithExifGps(jpeg, geo::fromEnu(gps, o.place), focal_35mm);
    io::writeFileAtomically(dir + "/" + photoStem(v.name) + ".jpg", [&](std::ostream& out) {
      out.write(reinterpret_cast<const char*>(bytes.data()),
                static_cast<std::streamsize>(bytes.size()));
    });
  }
  if (o.ground_control_points <= 0) return 0;

  // Ground points (sparse points below 0.5 m) nearest to a grid over 70 % of the world.
  const int side = std::max(2, static_cast<int>(std::lround(std::sqrt(o.ground_control_points))));
  double extent = 0;
  for (const auto& p : scene.points) {
    extent = std::max({extent, std::abs(double(p.xyz[0])), std::abs(double(p.xyz[1]))});
  }
  std::ostringstream text;
  text.precision(12);
  text << "EPSG:4326\n";
  int written = 0;
  for (int gy = 0; gy < side; ++gy) {
    for (int gx = 0; gx < side; ++gx) {
      const double x = 0.7 * extent * (2.0 * gx / (side - 1) - 1);
      const double y = 0.7 * extent * (2.0 * gy / (side - 1) - 1);
      const SynthPoint* best = nullptr;
      double best_d = 1e18;
      for (const auto& p : scene.points) {
        const double d = std::hypot(p.xyz[0] - x, p.xyz[1] - y);
        if (p.xyz[2] < 0.5 && d < best_d) best_d = d, best = &p;
      }
      if (best == nullptr) continue;
      const io::GeoPosition where =
          geo::fromEnu({best->xyz[0], best->xyz[1], best->xyz[2]}, o.place);
      const std::string name = "gcp-" + std::to_string(10 + written);
      int marks = 0;
      std::ostringstream lines;
      lines.precision(12);
      for (const SynthView& v : scene.views) {
        const PhotoPose p = photoPoseOf(v.camera);
        double xc[3];
        for (int r = 0; r < 3; ++r) {
          xc[r] = p.R[3 * r] * best->xyz[0] + p.R[3 * r + 1] * best->xyz[1] +
                  p.R[3 * r + 2] * best->xyz[2] + p.t[r];
        }
        if (xc[2] <= 0) continue;
        const double px = v.camera.fx * xc[0] / xc[2] + v.camera.cx;
        const double py = v.camera.fy * xc[1] / xc[2] + v.camera.cy;
        if (px < 2 || py < 2 || px > v.camera.width - 2 || py > v.camera.height - 2) continue;
        const float depth =
            v.depth[static_cast<std::size_t>(py) * v.camera.width + static_cast<std::size_t>(px)];
        if (std::abs(depth - xc[2]) > 0.5) continue;  // behind a building or a tree
        lines << where.longitude << " " << where.latitude << " " << where.altitude << " "
              << px + o.mark_noise_px * normal(rng) << " " << py + o.mark_noise_px * normal(rng)
              << " " << photoStem(v.name) << ".jpg " << name << "\n";
        ++marks;
      }
      if (marks < 2) continue;
      text << lines.str();
      ++written;
    }
  }
  io::writeTextFileAtomically(dir + "/gcp_list.txt", text.str());
  return written;
}

}  // namespace synth
}  // namespace sadsplat
