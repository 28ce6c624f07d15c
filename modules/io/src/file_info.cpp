#include "sadsplat/io/file_info.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/las.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/io/gltf_splats.h"
#include "sadsplat/io/splat_formats.h"

namespace sadsplat {
namespace io {
namespace {

// File-borne text for the terminal: control bytes (an escape sequence in a hand-edited file)
// shown as \xNN, never sent.
std::string printable(const std::string& text) {
  std::string out;
  for (unsigned char c : text) {
    if (c < 0x20 || c == 0x7F) {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02X", c);
      out += hex;
    } else {
      out.push_back(static_cast<char>(c));
    }
  }
  return out;
}

// One line: where the frame is on the Earth and how well the GPS fit it.
void describeGeoreference(std::ostream& out, const Georeference& g) {
  std::ostringstream geo;
  geo << std::fixed << std::setprecision(7) << "georeference: origin " << g.origin.latitude << ", "
      << g.origin.longitude << std::setprecision(2) << ", " << g.origin.altitude
      << " m (WGS84); frame east-north-up metres, z up; UTM EPSG:" << g.epsg_utm << "; ";
  if (g.control_points > 0) {
    geo << "fitted to " << g.control_points << " ground control points";
  } else {
    geo << g.inliers << " of " << g.photos_with_gps << " photos' GPS within the fit"
        << (g.consensus ? "" : " (no consensus: the fit of all; positions can be off by the RMS)");
  }
  geo << ", RMS " << g.rms_metres << " m\n";
  if (!g.up_source.empty()) {
    geo << "georeference: up from " << printable(g.up_source) << "; horizontal RMS "
        << g.horizontal_rms_metres << " m, vertical " << g.vertical_rms_metres << " m";
    if (g.ground_tilt_deg >= 0) geo << "; ground plane " << g.ground_tilt_deg << " deg from level";
    if (g.check_points > 0) {
      geo << "; " << g.check_points << " check points: RMSE horizontal " << std::setprecision(3)
          << g.check_rmse_horizontal << " m, vertical " << g.check_rmse_vertical << " m";
    }
    geo << "\n";
  }
  if (!g.trustworthy()) {
    geo << "georeference: DOUBTFUL:";
    for (const auto& d : g.doubts) geo << " " << printable(d) << ";";
    if (!g.consensus) geo << " no consensus with the GPS;";
    geo << " map positions, heights and areas can be wrong\n";
  }
  out << geo.str();
}

template <typename Range, typename GetXyz>
void describeBounds(std::ostream& out, const Range& points, GetXyz xyz) {
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                 std::numeric_limits<float>::max()};
  float hi[3] = {-lo[0], -lo[1], -lo[2]};
  bool any = false;
  std::size_t invalid = 0;
  for (const auto& p : points) {
    const auto v = xyz(p);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
      ++invalid;  // NaN: PCL's invalid point (readers refuse infinite coordinates)
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
    }
    any = true;
  }
  if (invalid > 0) out << "invalid points (NaN coordinates): " << invalid << "\n";
  if (!any) {
    out << "bounding box: (empty)\n";
    return;
  }
  out << std::setprecision(4) << "bounding box: [" << lo[0] << ", " << lo[1] << ", " << lo[2]
      << "] .. [" << hi[0] << ", " << hi[1] << ", " << hi[2] << "]\n";
}

void describeGaussians(std::ostream& out, const pcl::PointCloud<GaussianPoint>& cloud) {
  out << "gaussians: " << cloud.size() << "\n";
  describeBounds(out, cloud, [](const GaussianPoint& p) {
    return std::array<float, 3>{p.x, p.y, p.z};
  });
  std::size_t labelled = 0;
  std::uint32_t max_label = 0;
  for (const auto& p : cloud) {
    if (p.label != kUnlabelled) {
      ++labelled;
      max_label = std::max(max_label, p.label);
    }
  }
  out << "labelled gaussians: " << labelled;
  if (labelled) out << " (class ids up to " << max_label << ")";
  out << "\n";
  if (labelled) {
    std::map<std::uint32_t, std::size_t> histogram;
    for (const auto& p : cloud) {
      if (p.label != kUnlabelled) ++histogram[p.label];
    }
    out << "gaussians per class id:";
    for (const auto& [id, count] : histogram) out << " " << id << ":" << count;
    out << "\n";
  }
}

// A block run's partition (blocks.json): the grid and each block's training views.
void describeBlocks(std::ostream& out, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(readWholeFile(path));
    out << "blocks: " << j.at("rows").get<int>() << " x " << j.at("columns").get<int>()
        << " grid, trained apart and merged (blocks/); training views per block:";
    for (const auto& b : j.at("blocks")) out << " " << b.at("views").size();
    out << "\n";
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "blocks", "the partition `train --blocks` writes", printable(e.what()));
  }
}

void describeLas(std::ostream& out, const std::string& path) {
  std::map<int, std::size_t> histogram;
  const LasHeader h =
      forEachLasPoint(path, [&](const LasPoint& p) { ++histogram[p.classification]; });
  std::string crs = "none";
  if (!h.wkt.empty()) {  // the name: the first quoted string of the WKT
    const std::size_t a = h.wkt.find('"'), b = h.wkt.find('"', a + 1);
    crs = a != std::string::npos && b != std::string::npos ? h.wkt.substr(a + 1, b - a - 1)
                                                           : "(WKT without a name)";
  }
  out << path << ": LAS 1." << h.version_minor << ", point format " << h.point_format << "\n"
      << "points: " << h.point_count << "\n"
      << "CRS: " << printable(crs) << "\n"
      << std::fixed << std::setprecision(3) << "bounding box: [" << h.min[0] << ", " << h.min[1]
      << ", " << h.min[2] << "] .. [" << h.max[0] << ", " << h.max[1] << ", " << h.max[2] << "]\n";
  out << "points per ASPRS class:";
  for (const auto& [code, count] : histogram) {
    const auto it = asprsClassNames().find(code);
    out << " " << code << " (" << (it != asprsClassNames().end() ? it->second : "user")
        << "):" << count;
  }
  out << "\n";
}

void describeClamped(std::ostream& out, std::size_t clamped) {
  if (clamped > 0) {
    out << "opacities clamped: " << clamped << " infinite logits read as +-" << kMaxOpacityLogit
        << "\n";
  }
}

void describeSemantic(std::ostream& out, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud) {
  out << "points: " << cloud.size() << "\n";
  describeBounds(out, cloud, [](const pcl::PointXYZRGBL& p) {
    return std::array<float, 3>{p.x, p.y, p.z};
  });
  std::map<std::uint32_t, std::size_t> per_label;
  for (const auto& p : cloud) ++per_label[p.label];
  out << "points per class id:";
  for (const auto& [label, n] : per_label) {
    out << " ";
    if (label == kUnlabelled) {
      out << "none";
    } else {
      out << label;
    }
    out << "=" << n;
  }
  out << "\n";
}

void describeScene(std::ostream& out, const Scene& scene) {
  std::size_t train = 0, test = 0, labelled = 0;
  for (const auto& v : scene.views) {
    train += v.train;
    test += v.test;
    labelled += v.labelled;
  }
  out << "views: " << scene.views.size() << " (train " << train << ", test " << test
      << ", labelled " << labelled << ")\n";
  if (!scene.views.empty()) {
    out << "image size: " << scene.views[0].camera.width << "x" << scene.views[0].camera.height
        << "\n";
  }
  out << "sparse points: " << scene.points.size() << "\n";
  describeBounds(out, scene.points, [](const ScenePoint& p) { return p.xyz; });
  if (scene.georeference) {
    describeGeoreference(out, *scene.georeference);
  } else {
    out << "georeference: none (an SfM frame: no metres, no up)\n";
  }
  // Kept pseudo-label pixels per class, over the views that have pseudo-labels.
  std::vector<std::size_t> kept_pixels(scene.classes.size(), 0);
  std::size_t pseudo_views = 0, targets = 0, kept_targets = 0, pixels = 0, kept = 0;
  std::string backend;
  for (const auto& v : scene.views) {
    if (v.pseudo.empty()) continue;
    ++pseudo_views;
    backend = v.pseudo.backend;
    targets += static_cast<std::size_t>(v.pseudo.num_targets);
    kept_targets += static_cast<std::size_t>(
        std::count(v.pseudo.kept.begin(), v.pseudo.kept.end(), static_cast<std::uint8_t>(1)));
    for (std::int16_t l : v.pseudo.labelMap()) {
      ++pixels;
      if (l < 0) continue;
      ++kept;
      if (static_cast<std::size_t>(l) < kept_pixels.size()) ++kept_pixels[l];
    }
  }
  if (pseudo_views > 0) {
    std::ostringstream share;
    share << std::fixed << std::setprecision(1) << 100.0 * kept / pixels;
    out << "pseudo-labels: " << pseudo_views << " views (" << printable(backend) << "), "
        << kept_targets << " of " << targets << " targets kept, " << share.str()
        << " % of their pixels labelled\n";
  }
  out << "classes: " << scene.classes.size() << "\n";
  for (std::size_t i = 0; i < scene.classes.size(); ++i) {
    const auto& c = scene.classes[i];
    out << "  " << i << " " << printable(c.name) << " rgb(" << int(c.color[0]) << ","
        << int(c.color[1]) << "," << int(c.color[2]) << ") \"" << printable(c.prompt) << "\"";
    if (pseudo_views > 0) out << ", " << kept_pixels[i] << " pseudo-labelled pixels";
    out << "\n";
  }
}

}  // namespace

std::string describeFile(const std::string& path) {
  std::ostringstream out;
  if (!pathExists(path)) throw Error(path, "file", "an existing file or directory", "missing");
  if (isDirectory(path)) {
    const std::string ext = lowerExtension(path);
    if (ext == ".ply" || ext == ".pcd" || ext == ".splat" || ext == ".spz" || ext == ".sog" ||
        ext == ".glb") {
      throw Error(path, "file", "a " + ext + " file", "a directory");
    }
    if (RunDirectory::isRun(path)) {
      // A run directory: its model, and the frame it is in.
      const RunDirectory run(path);
      out << path << ": run directory (model.ply below)\n";
      if (optionalFileExists(run.georeference())) {
        describeGeoreference(
            out, georeferenceFromJson(readWholeFile(run.georeference()), run.georeference()));
      } else {
        out << "georeference: none (the scene's SfM frame)\n";
      }
      if (optionalFileExists(run.blocksJson())) describeBlocks(out, run.blocksJson());
      out << describeFile(run.model());
      return out.str();
    }
    out << path << ": scene directory\n";
    describeScene(out, importScene(path));
    return out.str();
  }
  requireRegularFile(path);  // a FIFO or device would block the reads below
  const std::string ext = lowerExtension(path);
  if (isSceneCache(path)) {
    out << describeSceneCache(path, readSceneCache(path));
  } else if ((ext == ".ply" || ext == ".pcd") && cloudKind(path) == CloudKind::kSemantic) {
    out << path << ": semantic point cloud (x y z colour label)\n";
    describeSemantic(out, readSemanticCloud(path));
  } else if (ext == ".ply" && isCompressedPly(path)) {
    CompressedPlyInfo info;
    const auto cloud = readCompressedPly(path, &info);
    out << path << ": PlayCanvas compressed PLY (" << info.chunks << " chunks of 256)\n"
        << "SH degree: " << info.sh_degree << "\n";
    describeClamped(out, info.clamped_opacities);
    describeGaussians(out, cloud);
  } else if (ext == ".ply") {
    PlyFileInfo info;
    const auto cloud = readGaussianPly(path, &info);
    out << path << ": 3DGS PLY (" << info.format << ")\n"
        << "SH degree: " << info.sh_degree << "\n"
        << "semantic properties: " << (info.has_semantic ? "yes" : "no") << " (feature dim "
        << info.feature_dim << ")\n";
    if (!info.ignored_properties.empty()) {
      out << "ignored properties:";
      for (const auto& n : info.ignored_properties) out << " " << n;
      out << "\n";
    }
    describeClamped(out, info.clamped_opacities);
    describeGaussians(out, cloud);
  } else if (ext == ".spz") {
    SpzFileInfo info;
    const auto cloud = readSpz(path, &info);
    out << path << ": SPZ version " << info.version << " (RUB axes on disk, read as RDF)\n"
        << "SH degree: " << info.sh_degree
        << (info.sh_degree > kMaxShDegree ? " (band 4 not read)" : "") << "\n"
        << "position step: 1/" << (1u << info.fractional_bits) << "\n"
        << "antialiased: " << (info.antialiased ? "yes" : "no") << "\n";
    if (info.extensions) out << "extensions: present (skipped)\n";
    describeClamped(out, info.clamped_opacities);
    describeGaussians(out, cloud);
  } else if (ext == ".glb") {
    GltfSplatInfo info;
    const auto cloud = readSplatGlb(path, &info);
    out << path << ": glTF KHR_gaussian_splatting (" << (info.spz ? "SPZ payload" : "plain accessors")
        << ", glTF y-up axes)\n"
        << "SH degree: " << info.sh_degree << "\n"
        << "classes: ";
    if (info.class_names.empty()) out << "none";
    for (std::size_t c = 0; c < info.class_names.size(); ++c) {
      out << (c ? ", " : "") << info.class_names[c];
    }
    out << "\n";
    describeGaussians(out, cloud);
  } else if (ext == ".sog") {
    SogFileInfo info;
    const auto cloud = readSog(path, &info);
    out << path << ": PlayCanvas SOG version " << info.version << "\n"
        << "SH degree: " << info.sh_bands << "\n";
    describeClamped(out, info.clamped_opacities);
    describeGaussians(out, cloud);
  } else if (ext == ".splat") {
    out << path << ": .splat web-viewer splats (no semantic fields)\n";
    describeGaussians(out, readSplat(path));
  } else if (ext == ".las") {
    describeLas(out, path);
  } else if (ext == ".pcd") {
    out << path << ": PCD of GaussianPoint\n";
    describeGaussians(out, loadGaussianPcd(path));
  } else {
    throw Error(path, "file type",
                "a .ply, .pcd, .splat, .spz, .sog, .glb or .las file, a scene cache or a scene directory",
                ext.empty() ? "no extension" : ext);
  }
  // Whatever else came from the file: no control byte reaches the terminal (the lines stay).
  std::string text = out.str(), shown;
  std::size_t start = 0;
  for (std::size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1) {
    shown += printable(text.substr(start, nl - start)) + "\n";
  }
  return shown + printable(text.substr(start));
}

std::string describeSceneCache(const std::string& path, const Scene& scene) {
  std::ostringstream out;
  out << path << ": scene cache (version " << sceneCacheVersion(path) << ")\n";
  describeScene(out, scene);
  return out.str();
}

std::string describeCameras(const std::string& path) {
  const Scene scene = isDirectory(path) ? importScene(path) : readSceneCache(path);
  std::ostringstream out;
  out.precision(17);
  out << "name,width,height,fx,fy,cx,cy,qw,qx,qy,qz,tx,ty,tz,role\n";
  for (const View& v : scene.views) {
    const PinholeCamera& c = v.camera;
    out << printable(v.name) << "," << c.width << "," << c.height << "," << c.fx << "," << c.fy
        << "," << c.cx << "," << c.cy;
    for (double q : c.qvec) out << "," << q;
    for (double t : c.tvec) out << "," << t;
    out << "," << (v.test ? "test" : v.train ? "train" : "none") << "\n";
  }
  return out.str();
}

}  // namespace io
}  // namespace sadsplat
