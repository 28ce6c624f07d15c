// A TileTree as a 3D Tiles 1.1 tileset (see tileset_writer.h).
#include "sadsplat/tiles/tileset_writer.h"

#include <nlohmann/json.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/gaussian_transform.h"
#include "sadsplat/io/atomic_file.h"

namespace sadsplat {
namespace tiles {
namespace {

using json = nlohmann::json;

json boxOf(const Tile& t) {
  json box = json::array();
  for (int k = 0; k < 3; ++k) box.push_back(0.5 * (t.lo[k] + t.hi[k]));
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 3; ++k) box.push_back(k == axis ? 0.5 * (t.hi[k] - t.lo[k]) : 0.0);
  }
  return box;
}

}  // namespace

Eigen::Matrix3d zUpToGltfAxes() {
  Eigen::Matrix3d m;
  m << 1, 0, 0,  //
      0, 0, 1,   //
      0, -1, 0;
  return m;
}

TilesetSummary writeTileset(const std::string& dir, const TileTree& tree,
                            const TilesetOptions& options) {
  if (tree.tiles.empty()) throw Error(dir, "tile tree", "at least the root tile", "empty");
  json extras;
  try {
    extras = json::parse(options.extras_json);
  } catch (const json::exception& e) {
    throw Error(dir, "tileset extras", "a JSON object", e.what());
  }
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(dir) / "tiles", ec);
  if (ec) throw Error(dir, "folder", "a folder that can be made", ec.message());
  TilesetSummary summary;
  summary.tiles = tree.tiles.size();
  summary.leaves = tree.leaves();
  summary.depth = tree.depth();
  std::vector<json> nodes(tree.tiles.size());
  const Eigen::Matrix3d to_gltf = zUpToGltfAxes();
  for (std::size_t i = 0; i < tree.tiles.size(); ++i) {
    const Tile& t = tree.tiles[i];
    const std::string uri =
        "tiles/" + std::to_string(t.level) + "_" + std::to_string(i) + ".glb";
    pcl::PointCloud<GaussianPoint> content;
    filters::transformGaussians(t.content, content, to_gltf);
    const std::string path = (std::filesystem::path(dir) / uri).string();
    io::writeSplatGlb(path, content, options.content);
    summary.bytes += std::filesystem::file_size(path);
    summary.max_tile_splats = std::max(summary.max_tile_splats, t.content.size());
    if (t.leaf()) summary.leaf_splats += t.content.size();
    nodes[i] = {{"boundingVolume", {{"box", boxOf(t)}}},
                {"geometricError", t.geometric_error},
                {"content", {{"uri", uri}}}};
    if (!t.leaf()) nodes[i]["refine"] = "REPLACE";
  }
  // Children after parents: fill bottom-up.
  for (std::size_t i = tree.tiles.size(); i-- > 0;) {
    const Tile& t = tree.tiles[i];
    if (t.leaf()) continue;
    json children = json::array();
    for (std::size_t c : t.children) children.push_back(std::move(nodes[c]));
    nodes[i]["children"] = std::move(children);
  }
  json root = std::move(nodes[0]);
  root["refine"] = "REPLACE";
  if (options.root_transform) root["transform"] = *options.root_transform;
  const Tile& r = tree.tiles[0];
  double diagonal = 0;
  for (int k = 0; k < 3; ++k) diagonal += (r.hi[k] - r.lo[k]) * (r.hi[k] - r.lo[k]);
  summary.root_error = r.geometric_error;
  json used = options.content.spz
                  ? json::array({"KHR_gaussian_splatting", "KHR_gaussian_splatting_compression_spz_2"})
                  : json::array({"KHR_gaussian_splatting"});
  json required = used;
  if (!options.content.classes.empty()) {
    used.push_back("EXT_mesh_features");
    used.push_back("EXT_structural_metadata");
  }
  json tileset = {
      {"asset", {{"version", "1.1"}, {"generator", options.content.generator}}},
      {"geometricError", std::max(std::sqrt(diagonal), 2.0 * r.geometric_error)},
      {"extensionsUsed", json::array({"3DTILES_content_gltf"})},
      {"extensions",
       {{"3DTILES_content_gltf", {{"extensionsUsed", used}, {"extensionsRequired", required}}}}},
      {"root", std::move(root)}};
  if (!extras.empty()) tileset["extras"] = extras;
  const std::string text = tileset.dump(1);
  io::writeTextFileAtomically((std::filesystem::path(dir) / "tileset.json").string(), text + "\n");
  summary.bytes += text.size() + 1;
  return summary;
}

}  // namespace tiles
}  // namespace sadsplat
