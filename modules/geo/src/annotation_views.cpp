#include "sadsplat/geo/annotation_views.h"

#include <algorithm>
#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/map_frame.h"

namespace sadsplat {
namespace geo {
namespace {

// The footprint cells view `view` sees: cells of the points that project into its image.
std::vector<char> footprintCellsSeen(const io::View& view, const io::Scene& scene,
                                     const std::vector<int>& cell_of, std::size_t cells) {
  std::vector<char> seen(cells, 0);
  const io::PointProjector camera(view.camera);
  double u = 0, v = 0, z = 0;
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    if (cell_of[i] >= 0 && camera.project(scene.points[i].xyz, &u, &v, &z)) seen[cell_of[i]] = 1;
  }
  return seen;
}

int newFootprintCells(const std::vector<char>& seen, const std::vector<char>& covered) {
  int n = 0;
  for (std::size_t c = 0; c < seen.size(); ++c) n += seen[c] && !covered[c];
  return n;
}

void addFootprintCells(std::vector<char>* covered, const std::vector<char>& seen) {
  for (std::size_t c = 0; c < seen.size(); ++c) (*covered)[c] |= seen[c];
}

}  // namespace

void AnnotationViewOptions::check(const std::string& origin) const {
  if (count < 1) throw Error(origin, "count", "at least 1 view", std::to_string(count));
  if (cells < 2 || cells > 4096)
    throw Error(origin, "cells", "2 to 4096 cells along the longer side", std::to_string(cells));
}

AnnotationViews chooseAnnotationViews(const io::Scene& scene, const AnnotationViewOptions& options,
                                      const std::string& origin) {
  options.check(origin);
  if (scene.points.empty())
    throw Error(origin, "points", "sparse points to place the views' footprints", "none");
  std::vector<int> candidates;
  for (std::size_t v = 0; v < scene.views.size(); ++v)
    if (scene.views[v].train && !scene.views[v].test) candidates.push_back(static_cast<int>(v));
  if (candidates.empty()) throw Error(origin, "split", "at least one training view", "none");

  // The footprint: square cells on the ground plane over the points' 1st..99th percentiles.
  const GroundPoints ground = groundPoints(scene);
  const std::size_t np = scene.points.size();
  const std::vector<double>&es = ground.e, &ns = ground.n;
  const double e0 = ground.e0, e1 = ground.e1, n0 = ground.n0, n1 = ground.n1;
  AnnotationViews out;
  out.cell_size = std::max({e1 - e0, n1 - n0, 1e-9}) / options.cells;
  const int ce = std::max(1, static_cast<int>(std::ceil((e1 - e0) / out.cell_size)));
  const int cn = std::max(1, static_cast<int>(std::ceil((n1 - n0) / out.cell_size)));
  const std::size_t cells = static_cast<std::size_t>(ce) * cn;
  std::vector<int> cell_of(np, -1);
  std::vector<char> footprint(cells, 0);
  for (std::size_t i = 0; i < np; ++i) {
    const int a = static_cast<int>(std::floor((es[i] - e0) / out.cell_size));
    const int b = static_cast<int>(std::floor((ns[i] - n0) / out.cell_size));
    if (a < 0 || b < 0 || a > ce || b > cn) continue;
    cell_of[i] = std::min(b, cn - 1) * ce + std::min(a, ce - 1);
    footprint[cell_of[i]] = 1;
  }
  out.footprint_cells = static_cast<int>(std::count(footprint.begin(), footprint.end(), 1));
  const double total = std::max(1, out.footprint_cells);

  std::vector<std::vector<char>> seen;
  std::vector<char> all(cells, 0), covered(cells, 0), used(candidates.size(), 0);
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    seen.push_back(footprintCellsSeen(scene.views[candidates[k]], scene, cell_of, cells));
    addFootprintCells(&all, seen.back());
    if (options.keep_labelled && scene.views[candidates[k]].labelled) {
      out.kept.push_back(candidates[k]);
      addFootprintCells(&covered, seen.back());
      used[k] = 1;
    }
  }
  out.all_share = std::count(all.begin(), all.end(), 1) / total;
  out.kept_share = std::count(covered.begin(), covered.end(), 1) / total;
  for (int pick = 0; pick < options.count; ++pick) {
    int best = -1, best_new = 0;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (used[k]) continue;
      const int n = newFootprintCells(seen[k], covered);
      if (n > best_new) {
        best = static_cast<int>(k);
        best_new = n;
      }
    }
    if (best < 0) break;  // no view adds a cell
    used[best] = 1;
    addFootprintCells(&covered, seen[best]);
    out.picked.push_back(candidates[best]);
    out.own_share.push_back(std::count(seen[best].begin(), seen[best].end(), 1) / total);
    out.cumulative_share.push_back(std::count(covered.begin(), covered.end(), 1) / total);
  }
  return out;
}

}  // namespace geo
}  // namespace sadsplat
