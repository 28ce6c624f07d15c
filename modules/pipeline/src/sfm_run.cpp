#include "sadsplat/pipeline/sfm_run.h"

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
#include <map>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/exif_orientation.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/georeference.h"

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/imgcodecs.hpp>
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
    const cv::Mat upright = cv::imread(from, cv::IMREAD_COLOR);
    if (upright.empty()) throw Error(from, "image data", "a readable photo", "cannot decode");
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
  std::vector<std::string> photos;
  for (const auto& e : fs::directory_iterator(o.photos)) {
    if (e.is_regular_file() && isPhoto(e.path().filename().string())) {
      photos.push_back(e.path().filename().string());
    }
  }
  std::sort(photos.begin(), photos.end());
  if (photos.size() < 2) {
    throw Error(o.photos, "photos", "at least 2 photos (.jpg, .jpeg, .png, .tif)",
                std::to_string(photos.size()));
  }
  const std::set<std::string> matchers = {"auto", "exhaustive", "sequential", "spatial"};
  if (!matchers.count(o.matcher)) {
    throw Error("<sfm options>", "matcher", "auto, exhaustive, sequential or spatial", o.matcher);
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
  int stage_number = 0;
  const auto stage = [&](const std::string& name, const std::vector<std::string>& args) {
    ++stage_number;
    say("[" + std::to_string(stage_number) + "/4] " + name + " ...");
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
  stage("feature_extractor",
        {o.colmap, "feature_extractor", "--database_path", db, "--image_path", image_path,
         "--ImageReader.single_camera", o.single_camera ? "1" : "0",
         "--SiftExtraction.max_image_size", size, "--SiftExtraction.num_threads", threads,
         "--SiftExtraction.use_gpu", "0"});
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
  stage(matcher + "_matcher", match);
  // Models of an earlier, failed run must not be taken for this run's.
  fs::remove_all(work + "/sparse");
  io::makeDirectory(work + "/sparse");
  stage("mapper", {o.colmap, "mapper", "--database_path", db, "--image_path", image_path,
                   "--output_path", work + "/sparse", "--Mapper.num_threads", threads});
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

  // The georeference: camera centres against the photos' GPS in east-north-up metres.
  std::vector<std::array<double, 3>> centres, targets;
  std::vector<const io::GeoPosition*> used;
  std::vector<std::string> gps_names;
  for (const auto& im : model.images) {
    const auto it = gps.find(im.name);
    if (it == gps.end()) continue;
    gps_names.push_back(im.name);
    const Eigen::Vector3d c =
        -rotationOf(im.qvec).transpose() * Eigen::Vector3d(im.tvec[0], im.tvec[1], im.tvec[2]);
    centres.push_back({c.x(), c.y(), c.z()});
    used.push_back(&it->second);
  }
  nlohmann::json georef_json = nullptr;
  if (used.size() >= 3) {
    io::GeoPosition origin;
    for (const auto* g : used) {
      origin.latitude += g->latitude / used.size();
      origin.longitude += g->longitude / used.size();
      origin.altitude += g->altitude / used.size();
    }
    for (const auto* g : used) targets.push_back(io::toEnu(*g, origin));
    std::vector<bool> inliers;
    try {
      io::Georeference geo;
      geo.sfm_to_local =
          io::fitSimilarity(centres, targets, o.gps_inlier_metres, &inliers, &geo.consensus);
      geo.origin = origin;
      geo.epsg_utm = io::utmEpsg(origin);
      geo.photos_with_gps = static_cast<int>(used.size());
      // Residuals per photo; the RMS is over the photos the fit used (the agreeing ones, or all).
      double sq = 0;
      int fitted = 0;
      nlohmann::json residuals = nlohmann::json::array();
      std::vector<std::pair<double, std::string>> off;  // photos outside the inlier distance
      for (std::size_t i = 0; i < centres.size(); ++i) {
        const auto x = geo.sfm_to_local.apply(centres[i]);
        double d2 = 0;
        for (int k = 0; k < 3; ++k) d2 += (x[k] - targets[i][k]) * (x[k] - targets[i][k]);
        residuals.push_back({{"photo", gps_names[i]},
                             {"metres", std::sqrt(d2)},
                             {"inlier", static_cast<bool>(inliers[i])}});
        if (inliers[i]) {
          ++geo.inliers;
        } else {
          off.emplace_back(std::sqrt(d2), gps_names[i]);
        }
        if (inliers[i] || !geo.consensus) sq += d2, ++fitted;
      }
      geo.rms_metres = std::sqrt(sq / std::max(1, fitted));
      report["gps_residuals"] = residuals;
      std::sort(off.rbegin(), off.rend());
      std::ostringstream warn;
      warn.precision(3);
      if (!geo.consensus) {
        warn << "warning: no 3 photos' GPS agree with the reconstruction within "
             << o.gps_inlier_metres << " m; georeferenced by the least-squares fit of all "
             << used.size() << " (RMS " << geo.rms_metres << " m), so positions in the outputs "
             << "can be off by that much. The reconstruction or the GPS is wrong: check the "
                "photos' overlap (sfm_report.json lists each photo's distance to its GPS), or "
                "raise --gps-inlier if the GPS is this noisy.\n";
      }
      if (!off.empty()) {
        warn << "warning: " << off.size() << " of " << used.size()
             << " photos' camera centres lie more than " << o.gps_inlier_metres
             << " m from their GPS:";
        for (std::size_t k = 0; k < std::min<std::size_t>(off.size(), 5); ++k) {
          warn << " " << off[k].second << " (" << off[k].first << " m)";
        }
        warn << (off.size() > 5 ? " ...\n" : "\n");
      }
      say(warn.str());
      transformModel(model, geo.sfm_to_local);
      io::writeFileAtomically(o.out + "/georeference.json",
                              [&](std::ostream& out) { out << io::georeferenceToJson(geo); });
      georef_json = nlohmann::json::parse(io::georeferenceToJson(geo));
      summary.georeferenced = true;
    } catch (const Error& e) {
      say(std::string("sfm: no georeference: ") + e.what() + "\n");
    }
  } else {
    say("sfm: no georeference (" + std::to_string(used.size()) +
        " registered photos with GPS; 3 needed): the model keeps COLMAP's frame\n");
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
    const auto g = io::georeferenceFromJson(io::readWholeFile(o.out + "/georeference.json"),
                                            o.out + "/georeference.json");
    done << "; georeferenced (" << g.inliers << " of " << g.photos_with_gps
         << " GPS positions within " << o.gps_inlier_metres << " m"
         << (g.consensus ? "" : ", no consensus: fit of all") << ", RMS " << g.rms_metres
         << " m, UTM EPSG:" << g.epsg_utm << ")";
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
