// A model for the globe: upright, placed, tiled (see globe_export.h).
#include "sadsplat/pipeline/globe_export.h"

#include <nlohmann/json.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/gaussian_transform.h"
#include "sadsplat/geo/geodesy.h"
#include "sadsplat/geo/las_export.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/tiles/tile_tree.h"
#include "sadsplat/tiles/tileset_writer.h"

namespace sadsplat {
namespace pipeline {
namespace {

// Where a client should look: the median centre of the Gaussians (floaters do not move it) and
// the half-diagonal of the middle half of them (the dense scene, not its outliers), z-up frame.
std::array<double, 4> lookAt(const pcl::PointCloud<GaussianPoint>& cloud) {
  std::array<std::vector<double>, 3> xyz;
  for (const GaussianPoint& p : cloud) {
    xyz[0].push_back(p.x);
    xyz[1].push_back(p.y);
    xyz[2].push_back(p.z);
  }
  auto quantile = [](std::vector<double>& v, double q) {
    const std::size_t k = static_cast<std::size_t>(q * (v.size() - 1));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[k];
  };
  std::array<double, 4> out{};
  double diagonal = 0;
  for (int k = 0; k < 3; ++k) {
    out[k] = quantile(xyz[k], 0.5);
    const double spread = quantile(xyz[k], 0.75) - quantile(xyz[k], 0.25);
    if (k < 2) diagonal += spread * spread;
  }
  out[3] = 0.5 * std::sqrt(diagonal);
  return out;
}

}  // namespace

void colorByClass(pcl::PointCloud<GaussianPoint>& cloud, const std::vector<ClassInfo>& classes) {
  constexpr float kC0 = 0.28209479177387814f;
  for (GaussianPoint& p : cloud) {
    for (int c = 0; c < 3; ++c) {
      const float rgb = p.label < classes.size() ? classes[p.label].color[c] / 255.0f : 0.5f;
      p.f_dc[c] = (rgb - 0.5f) / kC0;
    }
    std::fill(std::begin(p.f_rest), std::end(p.f_rest), 0.0f);
  }
}

UprightModel openUprightModel(const std::string& model_or_run) {
  const bool run = io::RunDirectory::isRun(model_or_run);
  const std::string model = run ? io::RunDirectory(model_or_run).model() : model_or_run;
  UprightModel m;
  pcl::PointCloud<GaussianPoint> cloud = io::readGaussians(model);
  const geo::LasExportOptions beside = geo::lasOptionsBeside(model_or_run);
  m.classes = beside.classes;
  m.georeference = beside.georeference;
  if (m.georeference) {
    m.cloud = std::move(cloud);
    std::ostringstream s;
    s << std::setprecision(10) << "east-north-up metres around lat " << m.georeference->origin.latitude
      << ", lon " << m.georeference->origin.longitude << ", alt "
      << m.georeference->origin.altitude << " m (georeference.json)";
    m.frame = s.str();
    return m;
  }
  std::array<double, 3> up = {0, -1, 0};
  m.frame = "local: up = -y (the 3DGS camera convention; no georeference.json, no run's scene)";
  if (run) {
    try {
      const io::RunRecord record = io::RunDirectory(model_or_run).readRecord();
      up = geo::sceneUp(loadScene(record.scene, record.scale));
      std::ostringstream s;
      s << std::setprecision(3) << "local: up = (" << up[0] << ", " << up[1] << ", " << up[2]
        << "), minus the mean viewing direction of the run's scene (no georeference.json)";
      m.frame = s.str();
    } catch (const Error& e) {
      m.frame += "; the run's scene could not be read: " + std::string(e.what());
    }
  }
  const geo::MapFrame local = geo::localMapFrame(up);
  Eigen::Matrix3d r;
  for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = local.scene_to_local[i];
  filters::transformGaussians(cloud, m.cloud, r);
  return m;
}

std::string exportTiles(const std::string& model_or_run, const std::string& out_dir,
                        const TilesExportOptions& options, std::ostream* progress) {
  const auto start = std::chrono::steady_clock::now();
  UprightModel m = openUprightModel(model_or_run);
  if (options.color_by_class) {
    if (m.classes.empty()) {
      throw Error(model_or_run, "--color-by-class", "a model with classes (classes.json)", "none");
    }
    colorByClass(m.cloud, m.classes);
  }
  if (progress) *progress << "model: " << m.cloud.size() << " Gaussians; frame: " << m.frame << "\n";
  tiles::TileTreeOptions tree_options;
  tree_options.max_splats = options.max_splats;
  tree_options.class_aware = options.class_aware;
  const tiles::TileTree tree = tiles::buildTileTree(m.cloud, tree_options);
  if (progress) {
    *progress << "tree: " << tree.tiles.size() << " tiles, " << tree.leaves() << " leaves, depth "
              << tree.depth() << "\n";
  }
  tiles::TilesetOptions t;
  t.content.spz = options.spz;
  t.content.sh_degree = options.sh_degree;
  t.content.classes = m.classes;
  nlohmann::json extras = {{"generator", "sadsplat tiles"}, {"frame", m.frame}};
  const std::array<double, 4> look = lookAt(m.cloud);
  if (m.georeference) {
    const io::GeoPosition at = geo::fromEnu({look[0], look[1], look[2]}, m.georeference->origin);
    extras["look_at"] = {{"latitude", at.latitude},
                         {"longitude", at.longitude},
                         {"height", at.altitude},
                         {"radius", look[3]}};
    const tiles::Tile& root = tree.tiles[0];
    const io::GeoPosition box = geo::fromEnu({0.5 * (root.lo[0] + root.hi[0]),
                                              0.5 * (root.lo[1] + root.hi[1]),
                                              0.5 * (root.lo[2] + root.hi[2])},
                                             m.georeference->origin);
    extras["root_box_centre"] = {
        {"latitude", box.latitude}, {"longitude", box.longitude}, {"height", box.altitude}};
    t.root_transform = geo::enuToEcefMatrix(m.georeference->origin);
    extras["georeferenced"] = true;
    extras["origin"] = {{"latitude", m.georeference->origin.latitude},
                        {"longitude", m.georeference->origin.longitude},
                        {"altitude", m.georeference->origin.altitude}};
  } else {
    extras["georeferenced"] = false;
    extras["look_at"] = {{"x", look[0]}, {"y", look[1]}, {"z", look[2]}, {"radius", look[3]}};
    extras["note"] = "local tileset: no georeference, no root transform (place it in the client)";
  }
  if (!m.classes.empty()) {
    nlohmann::json names = nlohmann::json::array();
    for (const ClassInfo& c : m.classes) names.push_back(c.name);
    extras["classes"] = names;
  }
  t.extras_json = extras.dump();
  const tiles::TilesetSummary s = tiles::writeTileset(out_dir, tree, t);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ostringstream out;
  out << std::fixed << std::setprecision(1) << out_dir << "/tileset.json: " << s.tiles
      << " tiles (" << s.leaves << " leaves, depth " << s.depth << "), " << s.leaf_splats
      << " Gaussians in the leaves, at most " << s.max_tile_splats << " per tile, "
      << (options.spz ? "SPZ" : "plain") << " content, " << s.bytes / 1e6 << " MB, root error "
      << s.root_error << " m, " << seconds << " s\n";
  if (m.georeference) {
    out << "on the globe: " << m.frame << "\n";
  } else {
    out << "local tileset (no georeference.json): no root transform; " << m.frame << "\n";
  }
  return out.str();
}

std::string exportGlb(const std::string& model_or_run, const std::string& out_path,
                      io::GltfSplatOptions options) {
  const UprightModel m = openUprightModel(model_or_run);
  pcl::PointCloud<GaussianPoint> gltf;
  filters::transformGaussians(m.cloud, gltf, tiles::zUpToGltfAxes());
  options.classes = m.classes;
  io::writeSplatGlb(out_path, gltf, options);
  return "glTF axes (y up) of the frame: " + m.frame;
}

}  // namespace pipeline
}  // namespace sadsplat
