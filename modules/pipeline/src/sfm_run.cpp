#include "sadsplat/pipeline/sfm_run.h"
#include "sadsplat/geo/geodesy.h"

#include <nlohmann/json.hpp>

#include <Eigen/Dense>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/gps_georeference.h"
#include "sadsplat/geo/ground_control.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/exif_orientation.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/georeference.h"
#include "sadsplat/io/image_file.h"

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#endif

extern char** environ;

namespace sadsplat {
namespace pipeline {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

bool onPath(const std::string& program) {
  if (program.find('/') != std::string::npos) return ::access(program.c_str(), X_OK) == 0;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (!dir.empty() && ::access((dir + "/" + program).c_str(), X_OK) == 0) return true;
  }
  return false;
}

// Runs `args` with stdout and stderr into `log`; COLMAP's Qt must not look for a display.
int runLogged(const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::strncmp(*e, "QT_QPA_PLATFORM=", 16) != 0) env_strings.emplace_back(*e);
  }
  env_strings.emplace_back("QT_QPA_PLATFORM=offscreen");
  std::vector<char*> env, argv;
  for (auto& s : env_strings) env.push_back(s.data());
  env.push_back(nullptr);
  std::vector<std::string> copy = args;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), env.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1;
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool isPhoto(const std::string& name) {
  const std::string ext = io::lowerExtension(name);
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".tif" || ext == ".tiff";
}

std::string lastLines(const std::string& path, int n) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty()) lines.push_back(line);
  }
  std::string out;
  for (std::size_t i = lines.size() > static_cast<std::size_t>(n) ? lines.size() - n : 0;
       i < lines.size(); ++i) {
    out += (out.empty() ? "" : " | ") + lines[i];
  }
  return out.empty() ? "no output" : out;
}

Eigen::Matrix3d rotationOf(const std::array<double, 4>& q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

std::array<double, 3> toArray(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::string fixed(double v, int digits = 2) {
  std::ostringstream s;
  s.precision(digits);
  s << std::fixed << v;
  return s.str();
}

// The sanity check every run prints: where up came from, how well the GPS agrees, how level
// the scene's own cues are after the fit, and the photos farthest from their GPS.
std::string describeGpsFit(const geo::GpsFit& fit) {
  const io::Georeference& g = fit.georeference;
  std::string text = "sfm: georeference from GPS: up from " + g.up_source + "; " +
                     std::to_string(g.inliers) + " of " + std::to_string(g.photos_with_gps) +
                     " photos agree within " + fixed(g.inlier_metres) + " m (noise measured " +
                     fixed(g.gps_noise_metres) + " m, stated or assumed " +
                     fixed(g.gps_accuracy_metres) + " m), RMS horizontal " +
                     fixed(g.horizontal_rms_metres) + " m, vertical " +
                     fixed(g.vertical_rms_metres) + " m (altitude: the median offset only)";
  if (g.up_source != "gps 3D fit") {
    text += ", scale +-" + fixed(100 * g.scale_uncertainty) + " %";
  }
  text += "\nsfm: level check after the fit: ground plane " +
          (g.ground_tilt_deg >= 0 ? fixed(g.ground_tilt_deg) + " deg" : std::string("none found")) +
          ", nadir views " +
          (g.views_tilt_deg >= 0 ? fixed(g.views_tilt_deg) + " deg" : std::string("not nadir")) +
          " from vertical\n";
  std::vector<std::pair<double, std::string>> off;
  for (const auto& r : fit.residuals) {
    if (!r.inlier) off.emplace_back(r.horizontal, r.photo);
  }
  std::sort(off.rbegin(), off.rend());
  if (!off.empty()) {
    text += "sfm: " + std::to_string(off.size()) + " photos' GPS disagree (horizontal):";
    for (std::size_t k = 0; k < std::min<std::size_t>(off.size(), 5); ++k) {
      text += " " + off[k].second + " (" + fixed(off[k].first, 1) + " m)";
    }
    text += off.size() > 5 ? " ...\n" : "\n";
  }
  return text;
}

std::string describeGcpFit(const geo::GcpFit& fit) {
  const io::Georeference& g = fit.georeference;
  std::string text = "sfm: georeference from " + std::to_string(g.control_points) +
                     " ground control points: RMS horizontal " + fixed(g.horizontal_rms_metres, 3) +
                     " m, vertical " + fixed(g.vertical_rms_metres, 3) + " m; ";
  if (g.check_points > 0) {
    text += std::to_string(g.check_points) + " check points: RMSE horizontal " +
            fixed(g.check_rmse_horizontal, 3) + " m, vertical " + fixed(g.check_rmse_vertical, 3) +
            " m\n";
  } else {
    text += "no check points (mark some CHK... or give >= 5 points): the accuracy is unchecked\n";
  }
  for (const auto& s : fit.skipped) text += "sfm: ground control point skipped: " + s + "\n";
  return text;
}

// PHOTOS/masks/: each photo's mask as COLMAP (<photo>.png), OpenDroneMap (<stem>_mask.<ext>) or
// nerfstudio-style (<stem>.png) name it.
std::map<std::string, std::string> photoMasks(const std::string& photos_dir,
                                              const std::vector<std::string>& photos) {
  std::map<std::string, std::string> masks;
  const std::string dir = photos_dir + "/masks";
  if (!io::isDirectory(dir)) return masks;
  for (const auto& p : photos) {
    const std::string stem = p.substr(0, p.find_last_of('.'));
    const std::string ext = p.substr(p.find_last_of('.'));
    for (const std::string& candidate :
         {dir + "/" + p + ".png", dir + "/" + stem + ".png", dir + "/" + stem + "_mask" + ext,
          dir + "/" + stem + "_mask.png"}) {
      if (io::optionalFileExists(candidate)) {
        masks[p] = candidate;
        break;
      }
    }
  }
  return masks;
}

#if SADSPLAT_HAVE_OPENCV
// A mask as COLMAP takes it: 8-bit, 0 = leave out, 255 = keep, the photo's size. No mask: all
// kept.
void writeBinaryMask(const std::string& mask, const std::string& photo, const std::string& out) {
  const cv::Mat image = io::decodeImage(photo, cv::IMREAD_COLOR, "photo");
  cv::Mat keep(image.size(), CV_8UC1, cv::Scalar(255));
  if (!mask.empty()) {
    const cv::Mat raw = io::decodeImage(mask, cv::IMREAD_GRAYSCALE, "mask");
    if (raw.size() != image.size()) {
      throw Error(mask, "size",
                  std::to_string(image.cols) + "x" + std::to_string(image.rows) + " (its photo)",
                  std::to_string(raw.cols) + "x" + std::to_string(raw.rows));
    }
    keep.setTo(0, raw == 0);
  }
  if (!cv::imwrite(out, keep)) throw Error(out, "file", "a writable mask", "cannot write");
}

// COLMAP's undistorted mask (interpolated, maybe JPEG) back to 0 / 255.
void binariseUndistortedMask(const std::string& in, const std::string& out) {
  const cv::Mat raw = io::decodeImage(in, cv::IMREAD_GRAYSCALE, "undistorted mask (COLMAP's)");
  cv::Mat keep;
  cv::threshold(raw, keep, 127, 255, cv::THRESH_BINARY);
  if (!cv::imwrite(out, keep)) throw Error(out, "file", "a writable mask", "cannot write");
}
#else
[[noreturn]] void writeBinaryMask(const std::string&, const std::string& photo,
                                  const std::string&) {
  throw Error(photo, "masks", "a build with OpenCV to read photo masks", "a build without it");
}
[[noreturn]] void binariseUndistortedMask(const std::string& in, const std::string&) {
  throw Error(in, "masks", "a build with OpenCV to read photo masks", "a build without it");
}
#endif

// The georeference of the undistorted `model` (the mapper's own model, `distorted_model`, shares
// its frame): from ground control points when given, else from the photos' GPS; what each fit
// found goes into the report and onto the terminal.
std::optional<io::Georeference> georeferenceModel(
    const io::ColmapModel& model, const std::string& distorted_model,
    const std::map<std::string, io::GeoPosition>& gps, const std::optional<geo::GcpList>& gcps,
    double gps_accuracy, nlohmann::json& report,
    const std::function<void(const std::string&)>& say) {
  std::vector<geo::GpsPhoto> gps_photos;
  int with_gps = 0;
  io::GeoPosition origin;
  for (const auto& im : model.images) {
    geo::GpsPhoto photo;
    photo.name = im.name;
    const Eigen::Matrix3d R = rotationOf(im.qvec);
    photo.centre = toArray(-R.transpose() * Eigen::Vector3d(im.tvec[0], im.tvec[1], im.tvec[2]));
    photo.viewing = toArray(R.transpose() * Eigen::Vector3d::UnitZ());
    const auto it = gps.find(im.name);
    if (it != gps.end()) {
      photo.stated_accuracy = it->second.horizontal_accuracy;
      origin.latitude += it->second.latitude, origin.longitude += it->second.longitude;
      origin.altitude += it->second.altitude, ++with_gps;
    }
    gps_photos.push_back(photo);
  }
  if (with_gps > 0) {
    origin.latitude /= with_gps, origin.longitude /= with_gps, origin.altitude /= with_gps;
  } else if (gcps) {
    for (const auto& p : gcps->points) {
      origin.latitude += p.wgs84.latitude / gcps->points.size();
      origin.longitude += p.wgs84.longitude / gcps->points.size();
      origin.altitude += p.wgs84.altitude / gcps->points.size();
    }
  }
  origin.horizontal_accuracy = 0;
  for (auto& photo : gps_photos) {
    const auto it = gps.find(photo.name);
    if (it != gps.end()) photo.gps = geo::toEnu(it->second, origin);
  }
  std::vector<std::array<double, 3>> points;
  for (const auto& p : model.points) points.push_back(p.xyz);

  std::optional<io::Georeference> georeference;
  if (with_gps >= 3) {
    try {
      const geo::GpsFit fit = geo::fitGpsGeoreference(gps_photos, points, origin, {gps_accuracy});
      nlohmann::json residuals = nlohmann::json::array();
      for (const auto& r : fit.residuals) {
        residuals.push_back({{"photo", r.photo},
                             {"metres", std::hypot(r.horizontal, r.vertical)},
                             {"horizontal", r.horizontal},
                             {"vertical", r.vertical},
                             {"inlier", r.inlier}});
      }
      report["gps_residuals"] = residuals;
      report["gps_georeference"] = nlohmann::json::parse(io::georeferenceToJson(fit.georeference));
      georeference = fit.georeference;
      say(describeGpsFit(fit));
    } catch (const Error& e) {
      say(std::string("sfm: no georeference from GPS: ") + e.what() + "\n");
    }
  } else if (!gcps) {
    say("sfm: no georeference (" + std::to_string(with_gps) +
        " registered photos with GPS; 3 needed): the model keeps COLMAP's frame\n");
  }
  std::optional<geo::GcpFit> gcp_fit;
  if (gcps) {
    // The photos' pixel marks are on the original photos: triangulate in COLMAP's own model
    // (distorted cameras, the same frame as the undistorted one). A reconstruction that cannot
    // place them keeps the GPS frame, said loudly, rather than losing the run.
    try {
      gcp_fit = geo::fitGcpGeoreference(io::readColmapModel(distorted_model), *gcps, origin);
    } catch (const Error& e) {
      say(std::string("WARNING: the ground control points could not be used: ") + e.what() + "\n");
      if (georeference) {
        georeference->doubts.push_back(std::string("the ground control points could not be "
                                                   "used (") +
                                       e.what() + ")");
      }
    }
  }
  if (gcp_fit) {
    const geo::GcpFit& fit = *gcp_fit;
    nlohmann::json residuals = nlohmann::json::array();
    for (const auto& r : fit.residuals) {
      residuals.push_back({{"name", r.name},
                           {"check", r.check},
                           {"horizontal", r.horizontal},
                           {"vertical", r.vertical},
                           {"reprojection_px", r.reprojection_px},
                           {"marks", r.marks}});
    }
    report["gcp_residuals"] = residuals;
    report["gcp_skipped"] = fit.skipped;
    report["gcp_file"] = gcps->path;
    io::Georeference g = fit.georeference;
    if (georeference) {
      // What the GPS fit said of the scene's own up stays as a check of the GCP frame.
      g.photos_with_gps = georeference->photos_with_gps;
      g.gps_accuracy_metres = georeference->gps_accuracy_metres;
      g.gps_noise_metres = georeference->gps_noise_metres;
    }
    georeference = g;
    say(describeGcpFit(fit));
  }
  return georeference;
}

// The model moved by x' = s R x + t: points move, cameras keep what they see.
void transformModel(io::ColmapModel& model, const io::Similarity& sim) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = sim.rotation[3 * r + c];
  const Eigen::Vector3d t(sim.translation[0], sim.translation[1], sim.translation[2]);
  for (auto& p : model.points) p.xyz = sim.apply(p.xyz);
  for (auto& im : model.images) {
    // x_cam = Rc x + tc = Rc R^T (x' - t) / s + tc; scaling camera coordinates by s changes no
    // projection: Rc' = Rc R^T, tc' = s tc - Rc' t.
    const Eigen::Matrix3d rc = rotationOf(im.qvec) * R.transpose();
    const Eigen::Vector3d tc =
        sim.scale * Eigen::Vector3d(im.tvec[0], im.tvec[1], im.tvec[2]) - rc * t;
    const Eigen::Quaterniond q(rc);
    im.qvec = {q.w(), q.x(), q.y(), q.z()};
    im.tvec = {tc.x(), tc.y(), tc.z()};
  }
}

}  // namespace

std::string uprightPhotos(const std::string& photos_dir, const std::vector<std::string>& photos,
                          const std::string& work_dir, int* rotated) {
  std::vector<int> orientation;
  for (const auto& p : photos) orientation.push_back(io::readExifOrientation(photos_dir + "/" + p));
  *rotated = static_cast<int>(
      std::count_if(orientation.begin(), orientation.end(), [](int o) { return o != 1; }));
  if (*rotated == 0) return photos_dir;
#if SADSPLAT_HAVE_OPENCV
  const std::string dir = work_dir + "/upright";
  io::makeDirectory(dir);
  for (std::size_t i = 0; i < photos.size(); ++i) {
    const std::string from = photos_dir + "/" + photos[i], to = dir + "/" + photos[i];
    if (orientation[i] == 1) {
      fs::copy_file(from, to, fs::copy_options::overwrite_existing);
      continue;
    }
    // imread applies the EXIF orientation unless told not to; the copy carries no EXIF, so
    // COLMAP reads it upright (the GPS is taken from the original).
    const cv::Mat upright = io::decodeImage(from, cv::IMREAD_COLOR, "photo");
    const std::string ext = io::lowerExtension(photos[i]);
    const bool jpeg = ext == ".jpg" || ext == ".jpeg";
    if (!cv::imwrite(to, upright,
                     jpeg ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 98} : std::vector<int>{})) {
      throw Error(to, "file", "a writable upright copy of " + from, "cannot write");
    }
  }
  return dir;
#else
  throw Error(photos_dir, "EXIF orientation",
              "photos stored upright (this build has no OpenCV to turn them)",
              std::to_string(*rotated) + " rotated photos");
#endif
}

SfmSummary sfmRun(const SfmOptions& o) {
  const auto start = Clock::now();
  std::ostream* log = o.progress;
  const auto say = [&](const std::string& text) {
    if (log) *log << text << std::flush;
  };
  if (!onPath(o.colmap)) {
    throw Error(
        o.colmap, "program",
        "COLMAP on the PATH (Debian: apt install colmap; scripts/setup_debian.sh installs it)",
        "missing");
  }
  if (!io::isDirectory(o.photos)) {
    throw Error(o.photos, "photos", "a folder of photos",
                io::pathExists(o.photos) ? "not a folder" : "missing");
  }
  const std::vector<std::string> photos = io::filesIn(o.photos, isPhoto);
  if (photos.size() < 2) {
    throw Error(o.photos, "photos", "at least 2 photos (.jpg, .jpeg, .png, .tif)",
                std::to_string(photos.size()));
  }
  const std::set<std::string> matchers = {"auto", "exhaustive", "sequential", "spatial"};
  if (!matchers.count(o.matcher)) {
    throw Error("<sfm options>", "matcher", "auto, exhaustive, sequential or spatial", o.matcher);
  }
  if (o.match_neighbors < 1) {
    throw Error("<sfm options>", "match neighbors", ">= 1", std::to_string(o.match_neighbors));
  }
  if (!(o.gps_accuracy >= 0) || !std::isfinite(o.gps_accuracy)) {
    throw Error("<sfm options>", "gps accuracy", "metres >= 0 (0: from the photos)",
                std::to_string(o.gps_accuracy));
  }
  if (o.max_image_size < 100) {
    throw Error("<sfm options>", "max image size", ">= 100 pixels",
                std::to_string(o.max_image_size));
  }
  if (io::pathExists(o.out + "/sparse") || io::pathExists(o.out + "/images")) {
    throw Error(o.out, "scene directory", "a new or empty folder",
                "one with images/ or sparse/ already");
  }
  const std::string work = o.out + "/colmap";
  io::makeDirectory(o.out);
  io::makeDirectory(work);
  const std::string db = work + "/database.db";
  if (io::pathExists(db)) fs::remove(db);

  // GPS first: it decides the matcher and the georeference.
  std::map<std::string, io::GeoPosition> gps;
  for (const auto& p : photos) {
    if (auto g = io::readExifGps(o.photos + "/" + p)) gps[p] = *g;
  }
  say("sfm: " + std::to_string(photos.size()) + " photos in " + o.photos + ", " +
      std::to_string(gps.size()) + " with GPS" +
      (io::haveExif() ? "" : " (this build reads no EXIF: no georeference)") + "\n");
  // Ground control points are checked before COLMAP runs: a bad file costs no reconstruction.
  const std::string gcp_path =
      !o.gcp.empty()
          ? o.gcp
          : (io::pathExists(o.photos + "/gcp_list.txt") ? o.photos + "/gcp_list.txt" : "");
  std::optional<geo::GcpList> gcps;
  if (!gcp_path.empty()) {
    gcps = geo::readGcpList(gcp_path, photos);
    say("sfm: " + std::to_string(gcps->points.size()) + " ground control points in " + gcp_path +
        " (" + gcps->crs + ")\n");
  }
  // COLMAP reads pixels as stored: photos with an EXIF rotation get upright copies first, so
  // that images/, the cameras and annotations drawn on the photos as viewers show them agree.
  int rotated = 0;
  const std::string image_path = uprightPhotos(o.photos, photos, work, &rotated);
  if (rotated > 0) {
    say("sfm: " + std::to_string(rotated) + " photos carry an EXIF rotation: upright copies in " +
        image_path + "\n");
  }
  std::string matcher = o.matcher;
  if (matcher == "auto") {
    matcher = photos.size() <= 40               ? "exhaustive"
              : gps.size() * 2 >= photos.size() ? "spatial"
                                                : "sequential";
  }
  const std::string threads = std::to_string(o.threads);
  const std::string size = std::to_string(o.max_image_size);
  nlohmann::json report = {{"photos", photos.size()},
                           {"photos_with_gps", gps.size()},
                           {"matcher", matcher},
                           {"max_image_size", o.max_image_size}};
  nlohmann::json stages = nlohmann::json::array();
  // Masks (PHOTOS/masks/): features outside them are not extracted, and the scene gets them
  // undistorted as its images are (scene/masks/<photo>.png), so training leaves those pixels out.
  const std::map<std::string, std::string> masks = photoMasks(o.photos, photos);
  const std::string feature_masks = work + "/feature_masks";
  if (!masks.empty()) {
    say("sfm: " + std::to_string(masks.size()) + " photos have a mask in " + o.photos + "/masks\n");
    fs::remove_all(feature_masks);
    io::makeDirectory(feature_masks);
    for (const auto& p : photos) {
      const auto it = masks.find(p);
      writeBinaryMask(it == masks.end() ? "" : it->second, o.photos + "/" + p,
                      feature_masks + "/" + p + ".png");
    }
  }
  const int stage_count = masks.empty() ? 4 : 5;
  int stage_number = 0;
  const auto stage = [&](const std::string& name, const std::vector<std::string>& args) {
    ++stage_number;
    say("[" + std::to_string(stage_number) + "/" + std::to_string(stage_count) + "] " + name +
        " ...");
    const auto t0 = Clock::now();
    const std::string stage_log = work + "/" + name + ".log";
    const int rc = runLogged(args, stage_log);
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    std::ostringstream took;
    took.precision(1);
    took << std::fixed << seconds;
    say(" " + took.str() + " s\n");
    stages.push_back({{"stage", name}, {"seconds", seconds}, {"exit", rc}});
    if (rc != 0) {
      throw Error(stage_log, "colmap " + name, "exit status 0",
                  std::to_string(rc) + ": " + lastLines(stage_log, 2));
    }
  };
  std::vector<std::string> extract = {o.colmap,
                                      "feature_extractor",
                                      "--database_path",
                                      db,
                                      "--image_path",
                                      image_path,
                                      "--ImageReader.single_camera",
                                      o.single_camera ? "1" : "0",
                                      "--SiftExtraction.max_image_size",
                                      size,
                                      "--SiftExtraction.num_threads",
                                      threads,
                                      "--SiftExtraction.use_gpu",
                                      "0"};
  if (!masks.empty()) extract.insert(extract.end(), {"--ImageReader.mask_path", feature_masks});
  stage("feature_extractor", extract);
  std::vector<std::string> match = {o.colmap,
                                    matcher + "_matcher",
                                    "--database_path",
                                    db,
                                    "--SiftMatching.num_threads",
                                    threads,
                                    "--SiftMatching.use_gpu",
                                    "0"};
  if (matcher == "sequential") {
    match.insert(match.end(), {"--SequentialMatching.overlap", "10"});
  }
  if (matcher == "spatial") {
    // COLMAP's defaults (50 neighbours within 100 m) match nearly every pair of a survey.
    match.insert(match.end(), {"--SpatialMatching.max_num_neighbors",
                               std::to_string(o.match_neighbors), "--SpatialMatching.max_distance",
                               o.match_distance > 0 ? std::to_string(o.match_distance) : "1e9"});
    report["match_neighbors"] = o.match_neighbors;
    report["match_distance"] = o.match_distance;
  }
  stage(matcher + "_matcher", match);
  // Models of an earlier, failed run must not be taken for this run's.
  fs::remove_all(work + "/sparse");
  io::makeDirectory(work + "/sparse");
  std::vector<std::string> mapper = {
      o.colmap,        "mapper",         "--database_path",      db,     "--image_path", image_path,
      "--output_path", work + "/sparse", "--Mapper.num_threads", threads};
  if (!o.refine_focal) mapper.insert(mapper.end(), {"--Mapper.ba_refine_focal_length", "0"});
  report["refine_focal"] = o.refine_focal;
  stage("mapper", mapper);
  // The mapper may leave several models (sparse/0, 1, ...): the one with most photos.
  std::string best;
  std::size_t best_images = 0;
  for (const auto& e : fs::directory_iterator(work + "/sparse")) {
    if (!e.is_directory()) continue;
    const io::ColmapModel m = io::readColmapModel(e.path().string());
    if (m.images.size() > best_images) best_images = m.images.size(), best = e.path().string();
  }
  if (best_images < 2) {
    throw Error(work + "/mapper.log", "reconstruction",
                "at least 2 registered photos (more overlap, or --matcher exhaustive)",
                std::to_string(best_images));
  }
  const std::string undistorted = o.out + "/.undistort";
  fs::remove_all(undistorted);
  stage("image_undistorter",
        {o.colmap, "image_undistorter", "--image_path", image_path, "--input_path", best,
         "--output_path", undistorted, "--max_image_size", size});
  io::ColmapModel model = io::readColmapModel(undistorted + "/sparse");
  if (!masks.empty()) {
    // COLMAP undistorts the masks as it did the photos: same cameras, same size. It reads by
    // content and writes by extension, so each mask goes in under its photo's name.
    const std::string mask_photos = work + "/mask_photos", mask_out = o.out + "/.undistort_masks";
    fs::remove_all(mask_photos);
    fs::remove_all(mask_out);
    io::makeDirectory(mask_photos);
    for (const auto& p : photos) {
      fs::copy_file(feature_masks + "/" + p + ".png", mask_photos + "/" + p,
                    fs::copy_options::overwrite_existing);
    }
    stage("image_undistorter (masks)",
          {o.colmap, "image_undistorter", "--image_path", mask_photos, "--input_path", best,
           "--output_path", mask_out, "--max_image_size", size});
    io::makeDirectory(o.out + "/masks");
    for (const auto& im : model.images) {
      if (!masks.count(im.name)) continue;  // a photo without a mask keeps every pixel
      binariseUndistortedMask(mask_out + "/images/" + im.name,
                              o.out + "/masks/" + im.name + ".png");
    }
    fs::remove_all(mask_out);
  }

  SfmSummary summary;
  summary.photos = static_cast<int>(photos.size());
  summary.registered = static_cast<int>(model.images.size());
  std::set<std::string> registered;
  for (const auto& im : model.images) registered.insert(im.name);
  for (const auto& p : photos) {
    if (!registered.count(p)) summary.unregistered.push_back(p);
  }
  summary.points = model.points.size();
  double error_sum = 0;
  for (const auto& p : model.points) error_sum += p.error;
  summary.mean_reprojection_error = model.points.empty() ? 0 : error_sum / model.points.size();

  std::optional<io::Georeference> georeference =
      georeferenceModel(model, best, gps, gcps, o.gps_accuracy, report, say);
  nlohmann::json georef_json = nullptr;
  if (georeference) {
    transformModel(model, georeference->sfm_to_local);
    io::writeFileAtomically(o.out + "/georeference.json", [&](std::ostream& out) {
      out << io::georeferenceToJson(*georeference);
    });
    georef_json = nlohmann::json::parse(io::georeferenceToJson(*georeference));
    summary.georeferenced = true;
    summary.georeference_doubtful = !georeference->trustworthy();
    if (summary.georeference_doubtful) {
      std::string text = "WARNING: the georeference is doubtful:";
      for (const auto& d : georeference->doubts) text += " " + d + ";";
      if (!georeference->consensus) text += " the GPS does not agree with the reconstruction;";
      say(text +
          " positions, heights and areas in the map products (ortho, DSM, LAS) can be "
          "wrong. Check sfm_report.json; ground control points (gcp_list.txt) fix it.\n");
    }
  }
  io::makeDirectory(o.out + "/sparse");
  io::writeColmapText(o.out + "/sparse/0", model);
  fs::rename(undistorted + "/images", o.out + "/images");
  fs::remove_all(undistorted);

  summary.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  report["stages"] = stages;
  report["registered"] = summary.registered;
  report["unregistered"] = summary.unregistered;
  report["points"] = summary.points;
  report["mean_reprojection_error_px"] = summary.mean_reprojection_error;
  report["georeference"] = georef_json;
  report["seconds"] = summary.seconds;
  io::writeFileAtomically(o.out + "/sfm_report.json",
                          [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  std::ostringstream done;
  done.precision(3);
  done << "sfm: registered " << summary.registered << " of " << summary.photos << " photos, "
       << summary.points << " points, mean reprojection error " << summary.mean_reprojection_error
       << " px";
  if (summary.georeferenced) {
    done << (summary.georeference_doubtful ? "; georeference DOUBTFUL (" : "; georeferenced (")
         << georeference->up_source << ", UTM EPSG:" << georeference->epsg_utm << ")";
  }
  done << "; " << summary.seconds << " s\n";
  if (!summary.unregistered.empty()) {
    done << "sfm: not registered (not in the scene):";
    for (const auto& n : summary.unregistered) done << " " << n;
    done << "\n";
  }
  say(done.str());
  return summary;
}

}  // namespace pipeline
}  // namespace sadsplat
