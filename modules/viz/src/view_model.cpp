#include "sadsplat/viz/view_model.h"

#include <nlohmann/json.hpp>

#include "json_text.h"
#include "short_name.h"

#include <cmath>
#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene_cache.h"

namespace sadsplat {
namespace viz {
namespace {

namespace fs = std::filesystem;

// A plain semantic point as a small, opaque, round Gaussian of its class colour.
pcl::PointCloud<GaussianPoint> pointsAsGaussians(const pcl::PointCloud<pcl::PointXYZRGBL>& in) {
  constexpr float kC0 = 0.28209479177387814f;
  pcl::PointCloud<GaussianPoint> out;
  out.resize(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    GaussianPoint& g = out[i];
    g.x = in[i].x;
    g.y = in[i].y;
    g.z = in[i].z;
    const float rgb[3] = {in[i].r / 255.0f, in[i].g / 255.0f, in[i].b / 255.0f};
    for (int c = 0; c < 3; ++c) g.f_dc[c] = (rgb[c] - 0.5f) / kC0;
    g.opacity = 6.0f;  // sigmoid ~ 1
    for (float& s : g.scale) s = std::log(0.05f);
    g.label = in[i].label;
    g.confidence = 1.0f;
  }
  return out;
}

}  // namespace

ViewModel loadViewModel(const std::string& path) {
  ViewModel m;
  std::string model = path;
  std::string classes_json;
  if (io::isDirectory(path)) {
    const io::RunDirectory run(path);
    model = run.model();
    if (!io::isRegularFile(model)) {
      throw Error(path, "run directory", "a training run with model.ply", "no model.ply");
    }
    const std::string run_json = run.runJson();
    if (io::isRegularFile(run_json)) {
      const auto run = parseOrDiscard(io::readWholeFile(run_json));
      if (!run.is_discarded() && run.contains("scene") && run["scene"].is_string()) {
        std::string scene = run["scene"].get<std::string>();
        if (io::isRegularFile(scene) && io::isSceneCache(scene)) {
          for (const io::View& v : io::readSceneCache(scene).views) {
            m.cameras.emplace_back(fs::path(v.name).stem().string(), v.camera);
          }
        }
      }
    }
  } else if (!io::pathExists(path)) {
    throw Error(path, "model", "a run directory, or a .ply / .pcd cloud", "no such file");
  }
  // classes.json beside the model: in its run directory, or beside a copied model.
  const fs::path folder = fs::path(model).parent_path();
  const std::string beside = io::RunDirectory(folder.empty() ? "." : folder.string()).classes();
  if (io::isRegularFile(beside)) classes_json = beside;
  m.name = shortName(path);
  if (io::cloudKind(model) == io::CloudKind::kSemantic) {
    m.gaussians = pointsAsGaussians(io::readSemanticCloud(model));
    m.semantic_only = true;
    m.has_semantic = true;
  } else if (io::lowerExtension(model) == ".ply") {
    io::PlyFileInfo info;
    m.gaussians = io::readGaussianPly(model, &info);
    m.has_semantic = info.has_semantic;
  } else {
    m.gaussians = io::readGaussians(model);
    if (io::lowerExtension(model) == ".pcd") {  // .splat and .spz have no semantic fields
      for (const std::string& f : io::pcdFieldNames(model)) m.has_semantic |= f == "label";
    }
  }
  if (!classes_json.empty()) m.classes = io::readClassesJson(classes_json);
  return m;
}

}  // namespace viz
}  // namespace sadsplat
