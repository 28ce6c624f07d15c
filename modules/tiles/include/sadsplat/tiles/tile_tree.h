#pragma once
/// \file tile_tree.h
/// \brief A quadtree of Gaussians over the ground with levels of detail: every Gaussian in exactly
/// one leaf, every inner tile a merge of the Gaussians below it to at most a splat budget, so a
/// client draws coarse tiles from afar and replaces them by their children as it comes closer.
///
/// The cloud is given in a z-up frame (east-north-up for a georeferenced model). A tile with more
/// Gaussians than the budget splits its rectangle in four at its middle (half-open cells; empty
/// quarters dropped; Gaussians at one spot split by index); its content is then
/// filters::compactGaussians of all Gaussians below it (class-aware by default). Geometric error
/// (metres, what 3D Tiles refines by): 0 for a leaf; for an inner tile the 90th percentile of its
/// merge groups' extent, and at least 1.5 x its children's largest, so it strictly decreases down
/// the tree.

#include <pcl/point_cloud.h>

#include <array>
#include <cstddef>
#include <vector>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace tiles {

/// \brief How the tree is made.
struct TileTreeOptions {
  std::size_t max_splats = 65536;  ///< no tile holds more Gaussians
  bool class_aware = true;         ///< merges keep classes apart
  int max_depth = 24;              ///< deeper tiles split by index, not space
};

/// \brief One tile: its box, error, children and content.
struct Tile {
  std::array<double, 3> lo{}, hi{};  ///< axis-aligned box of the content's 3-sigma extents
  double geometric_error = 0;        ///< 0 for a leaf
  double merge_extent = 0;  ///< CompactResult::group_extent of its merge (0: the Gaussians themselves)
  int level = 0;
  std::vector<std::size_t> children;  ///< indices into TileTree::tiles
  std::vector<std::size_t> source;    ///< leaf: indices of its Gaussians in the input cloud
  pcl::PointCloud<GaussianPoint> content;
  bool leaf() const { return children.empty(); }
};

/// \brief The tree; tiles[0] is the root, every parent before its children.
struct TileTree {
  std::vector<Tile> tiles;
  std::size_t leaves() const;
  int depth() const;
};

/// \brief Builds the tree of `cloud` (z-up frame).
/// \throws sadsplat::Error for an empty cloud or a budget of 0
TileTree buildTileTree(const pcl::PointCloud<GaussianPoint>& cloud, const TileTreeOptions& options);

}  // namespace tiles
}  // namespace sadsplat
