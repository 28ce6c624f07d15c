// The quadtree with merged levels of detail (see tile_tree.h).
#include "sadsplat/tiles/tile_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/gaussian_merge.h"

namespace sadsplat {
namespace tiles {
namespace {

constexpr double kErrorGrowth = 1.5;
constexpr double kSigmas = 3.0;

struct Rect {
  double x0, y0, x1, y1;
};

void boxOf(const pcl::PointCloud<GaussianPoint>& content, Tile& tile) {
  tile.lo.fill(std::numeric_limits<double>::max());
  tile.hi.fill(std::numeric_limits<double>::lowest());
  for (const GaussianPoint& p : content) {
    const double r =
        kSigmas * std::exp(double(std::max({p.scale[0], p.scale[1], p.scale[2]})));
    const double c[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      tile.lo[k] = std::min(tile.lo[k], c[k] - r);
      tile.hi[k] = std::max(tile.hi[k], c[k] + r);
    }
  }
}

class Builder {
 public:
  Builder(const pcl::PointCloud<GaussianPoint>& cloud, const TileTreeOptions& o)
      : cloud_(cloud), o_(o) {}

  // Adds the tile of `indices` inside `rect` and its subtree; returns its index.
  std::size_t add(std::vector<std::size_t> indices, const Rect& rect, int level) {
    const std::size_t index = tree.tiles.size();
    tree.tiles.emplace_back();
    tree.tiles[index].level = level;
    if (indices.size() <= o_.max_splats) {
      Tile& leaf = tree.tiles[index];
      leaf.content.reserve(indices.size());
      for (std::size_t i : indices) leaf.content.push_back(cloud_[i]);
      leaf.source = std::move(indices);
      boxOf(leaf.content, leaf);
      return index;
    }
    std::vector<std::size_t> children;
    double child_error = 0;
    for (auto& [part, sub] : split(indices, rect, level)) {
      const std::size_t child = add(std::move(part), sub, level + 1);
      children.push_back(child);
      child_error = std::max(child_error, tree.tiles[child].geometric_error);
    }
    pcl::PointCloud<GaussianPoint> below;
    below.reserve(indices.size());
    for (std::size_t i : indices) below.push_back(cloud_[i]);
    filters::CompactResult merged = filters::compactGaussians(below, o_.max_splats, o_.class_aware);
    Tile& tile = tree.tiles[index];
    tile.children = std::move(children);
    tile.content = std::move(merged.cloud);
    tile.merge_extent = merged.group_extent;
    tile.geometric_error = std::max(merged.group_extent,
                                    kErrorGrowth * child_error + 1e-3);
    boxOf(tile.content, tile);
    for (std::size_t c : tile.children) {
      for (int k = 0; k < 3; ++k) {
        tile.lo[k] = std::min(tile.lo[k], tree.tiles[c].lo[k]);
        tile.hi[k] = std::max(tile.hi[k], tree.tiles[c].hi[k]);
      }
    }
    return index;
  }

  TileTree tree;

 private:
  // The non-empty quarters of `rect` with their Gaussians (half-open cells), or, when space does
  // not separate them (one spot, or too deep), four runs of the index list.
  std::vector<std::pair<std::vector<std::size_t>, Rect>> split(const std::vector<std::size_t>& in,
                                                               const Rect& r, int level) const {
    std::vector<std::pair<std::vector<std::size_t>, Rect>> parts;
    const double mx = 0.5 * (r.x0 + r.x1), my = 0.5 * (r.y0 + r.y1);
    if (level < o_.max_depth) {
      const Rect quarters[4] = {{r.x0, r.y0, mx, my}, {mx, r.y0, r.x1, my},
                                {r.x0, my, mx, r.y1}, {mx, my, r.x1, r.y1}};
      std::vector<std::size_t> q[4];
      for (std::size_t i : in) {
        const int k = (cloud_[i].x >= mx ? 1 : 0) + (cloud_[i].y >= my ? 2 : 0);
        q[k].push_back(i);
      }
      for (int k = 0; k < 4; ++k) {
        if (q[k].size() == in.size()) break;  // space does not separate them
        if (!q[k].empty()) parts.emplace_back(std::move(q[k]), quarters[k]);
      }
      if (!parts.empty() && parts.size() > 1) return parts;
      parts.clear();
    }
    const std::size_t step = (in.size() + 3) / 4;
    for (std::size_t s = 0; s < in.size(); s += step) {
      parts.emplace_back(std::vector<std::size_t>(in.begin() + s,
                                                  in.begin() + std::min(in.size(), s + step)),
                         r);
    }
    return parts;
  }

  const pcl::PointCloud<GaussianPoint>& cloud_;
  const TileTreeOptions& o_;
};

}  // namespace

std::size_t TileTree::leaves() const {
  return static_cast<std::size_t>(
      std::count_if(tiles.begin(), tiles.end(), [](const Tile& t) { return t.leaf(); }));
}

int TileTree::depth() const {
  int d = 0;
  for (const Tile& t : tiles) d = std::max(d, t.level);
  return d;
}

TileTree buildTileTree(const pcl::PointCloud<GaussianPoint>& cloud,
                       const TileTreeOptions& options) {
  if (cloud.empty()) throw Error("<tiles>", "model", "at least one Gaussian", "none");
  if (options.max_splats == 0) throw Error("<tiles>", "--max-splats", "at least 1", "0");
  Rect r{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
         std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
  for (const GaussianPoint& p : cloud) {
    r.x0 = std::min(r.x0, double(p.x));
    r.y0 = std::min(r.y0, double(p.y));
    r.x1 = std::max(r.x1, double(p.x));
    r.y1 = std::max(r.y1, double(p.y));
  }
  // Square and slightly larger, so that the far edges fall inside the half-open cells.
  const double side = std::max(r.x1 - r.x0, r.y1 - r.y0) * 1.001 + 1e-6;
  r.x1 = r.x0 + side;
  r.y1 = r.y0 + side;
  std::vector<std::size_t> all(cloud.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  Builder b(cloud, options);
  b.add(std::move(all), r, 0);
  return std::move(b.tree);
}

}  // namespace tiles
}  // namespace sadsplat
