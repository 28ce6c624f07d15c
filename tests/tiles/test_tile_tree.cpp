// The tile tree's invariants: a partition of the Gaussians into leaves, budgets, errors, boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "sadsplat/common/error.h"
#include "sadsplat/tiles/tile_tree.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

pcl::PointCloud<GaussianPoint> spreadSplats(std::size_t n, std::uint64_t seed) {
  auto cloud = test::randomGaussians(n, seed, 3);
  for (auto& p : cloud) {
    p.x *= 50;  // a survey: wide, flat
    p.y *= 30;
    for (float& s : p.scale) s = -1.5f + 0.3f * s;
  }
  return cloud;
}

void expectInvariants(const tiles::TileTree& tree, std::size_t n, std::size_t budget) {
  std::vector<int> seen(n, 0);
  for (const tiles::Tile& t : tree.tiles) {
    EXPECT_LE(t.content.size(), budget);
    EXPECT_FALSE(t.content.empty());
    if (t.leaf()) {
      EXPECT_EQ(t.geometric_error, 0.0);
      EXPECT_EQ(t.source.size(), t.content.size());
      for (std::size_t i : t.source) ++seen[i];
      continue;
    }
    for (std::size_t c : t.children) {
      ASSERT_LT(c, tree.tiles.size());
      EXPECT_GT(c, static_cast<std::size_t>(&t - tree.tiles.data()));  // parents first
      EXPECT_LT(tree.tiles[c].geometric_error, t.geometric_error);
      EXPECT_EQ(tree.tiles[c].level, t.level + 1);
      for (int k = 0; k < 3; ++k) {
        EXPECT_LE(t.lo[k], tree.tiles[c].lo[k]);
        EXPECT_GE(t.hi[k], tree.tiles[c].hi[k]);
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seen[i], 1) << "Gaussian " << i;
}

TEST(TileTree, EveryGaussianLiesInExactlyOneLeafAndNoTileExceedsTheBudget) {
  const auto cloud = spreadSplats(5000, 31);
  tiles::TileTreeOptions o;
  o.max_splats = 300;
  const tiles::TileTree tree = tiles::buildTileTree(cloud, o);
  EXPECT_GT(tree.depth(), 1);
  EXPECT_GE(tree.leaves(), 5000u / 300);
  expectInvariants(tree, cloud.size(), o.max_splats);
  // Leaves hold the Gaussians themselves, bit for bit.
  for (const tiles::Tile& t : tree.tiles) {
    if (!t.leaf()) continue;
    for (std::size_t j = 0; j < t.source.size(); ++j) {
      EXPECT_TRUE(bitwiseEqual(t.content[j], cloud[t.source[j]]));
    }
  }
}

TEST(TileTree, ASmallModelIsOneLeaf) {
  const auto cloud = spreadSplats(100, 32);
  const tiles::TileTree tree = tiles::buildTileTree(cloud, {});
  ASSERT_EQ(tree.tiles.size(), 1u);
  EXPECT_TRUE(tree.tiles[0].leaf());
  expectInvariants(tree, cloud.size(), 100);
}

TEST(TileTree, GaussiansAtOneSpotStillSplitWithinTheBudget) {
  auto cloud = spreadSplats(400, 33);
  for (auto& p : cloud) p.x = p.y = p.z = 1.0f;
  tiles::TileTreeOptions o;
  o.max_splats = 50;
  o.class_aware = false;
  const tiles::TileTree tree = tiles::buildTileTree(cloud, o);
  expectInvariants(tree, cloud.size(), o.max_splats);
}

TEST(TileTree, BadInputIsRefused) {
  EXPECT_THROW(tiles::buildTileTree(pcl::PointCloud<GaussianPoint>(), {}), Error);
  tiles::TileTreeOptions o;
  o.max_splats = 0;
  EXPECT_THROW(tiles::buildTileTree(spreadSplats(10, 34), o), Error);
}

}  // namespace
}  // namespace sadsplat
