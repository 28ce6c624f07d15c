// The tileset on disk: tileset.json as 3D Tiles 1.1 asks, content that reads back, the root
// transform placing the ENU frame on Earth.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <functional>

#include "sadsplat/geo/geodesy.h"
#include "sadsplat/io/gltf_splats.h"
#include "sadsplat/tiles/tileset_writer.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using json = nlohmann::json;

TEST(TilesetWriter, WritesATilesetWhoseLeavesHoldTheModel) {
  test::TempDir dir;
  auto cloud = test::randomGaussians(2000, 41, 3);
  for (auto& p : cloud) {
    p.x *= 40;
    p.y *= 40;
    for (float& s : p.scale) s = -1.5f + 0.3f * s;
  }
  tiles::TileTreeOptions tree_options;
  tree_options.max_splats = 400;
  const tiles::TileTree tree = tiles::buildTileTree(cloud, tree_options);
  tiles::TilesetOptions o;
  o.root_transform = geo::enuToEcefMatrix({46.84, -91.99, 198.5});
  o.content.classes = {{"road", {1, 2, 3}, ""}, {"roof", {4, 5, 6}, ""}, {"tree", {7, 8, 9}, ""}};
  o.extras_json = R"({"georeferenced": true})";
  const tiles::TilesetSummary s = tiles::writeTileset(dir.path(), tree, o);
  EXPECT_EQ(s.tiles, tree.tiles.size());
  EXPECT_EQ(s.leaf_splats, cloud.size());
  EXPECT_LE(s.max_tile_splats, 400u);

  const json t = json::parse(test::readFile(dir.file("tileset.json")));
  EXPECT_EQ(t["asset"]["version"], "1.1");
  EXPECT_EQ(t["root"]["transform"].size(), 16u);
  EXPECT_EQ(t["root"]["refine"], "REPLACE");
  EXPECT_GT(t["geometricError"].get<double>(), t["root"]["geometricError"].get<double>());
  EXPECT_EQ(t["extensionsUsed"], json::array({"3DTILES_content_gltf"}));
  EXPECT_EQ(t["extensions"]["3DTILES_content_gltf"]["extensionsRequired"],
            json::array({"KHR_gaussian_splatting", "KHR_gaussian_splatting_compression_spz_2"}));
  EXPECT_EQ(t["extras"]["georeferenced"], true);
  std::size_t leaves = 0, splats = 0;
  std::function<void(const json&, double)> walk = [&](const json& tile, double parent_error) {
    EXPECT_LT(tile["geometricError"].get<double>(), parent_error);
    EXPECT_EQ(tile["boundingVolume"]["box"].size(), 12u);
    const std::string uri = tile["content"]["uri"];
    io::GltfSplatInfo info;
    const auto content = io::readSplatGlb(dir.file(uri), &info);
    const bool labelled = std::any_of(content.begin(), content.end(),
                                      [](const GaussianPoint& p) { return p.label < 3; });
    EXPECT_EQ(info.class_names.size(), labelled ? 3u : 0u);  // no feature IDs without a class
    if (!tile.contains("children")) {
      ++leaves;
      splats += content.size();
      return;
    }
    for (const json& c : tile["children"]) walk(c, tile["geometricError"].get<double>());
  };
  walk(t["root"], t["geometricError"].get<double>());
  EXPECT_EQ(leaves, tree.leaves());
  EXPECT_EQ(splats, cloud.size());
}

TEST(TilesetWriter, ContentIsTurnedToGltfYUp) {
  test::TempDir dir;
  auto cloud = test::randomGaussians(1, 42, 1);
  cloud[0].x = 1;
  cloud[0].y = 2;  // north
  cloud[0].z = 3;  // up
  const tiles::TileTree tree = tiles::buildTileTree(cloud, {});
  tiles::TilesetOptions o;
  o.content.spz = false;
  tiles::writeTileset(dir.path(), tree, o);
  const json t = json::parse(test::readFile(dir.file("tileset.json")));
  EXPECT_FALSE(t["root"].contains("transform"));  // local
  const auto content = io::readSplatGlb(dir.file(t["root"]["content"]["uri"]));
  EXPECT_FLOAT_EQ(content[0].x, 1);
  EXPECT_FLOAT_EQ(content[0].y, 3);   // glTF y: up
  EXPECT_FLOAT_EQ(content[0].z, -2);  // glTF z: south
}

}  // namespace
}  // namespace sadsplat
