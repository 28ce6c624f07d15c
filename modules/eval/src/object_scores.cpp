#include "sadsplat/eval/object_scores.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <tuple>
#include <unordered_map>

namespace sadsplat {
namespace eval {
namespace {

std::size_t findRoot(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

struct Box {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  void add(const std::array<double, 2>& p) {
    x0 = std::min(x0, p[0]), y0 = std::min(y0, p[1]);
    x1 = std::max(x1, p[0]), y1 = std::max(y1, p[1]);
  }
};

// Points binned into cubic cells of side `cell`: every point within `cell` of a point lies in one
// of the 27 cells around it.
class CellGrid {
 public:
  CellGrid(const std::vector<std::array<float, 3>>& points, double cell)
      : points_(points), cell_(cell) {
    for (std::size_t i = 0; i < points.size(); ++i) cells_[keyOf(points[i])].push_back(i);
  }
  // Calls f(j, squared distance) for every other point j in the 27 cells around point i.
  template <class F>
  void forEachNear(std::size_t i, F&& f) const {
    const auto [kx, ky, kz] = keyOf(points_[i]);
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(Key{kx + dx, ky + dy, kz + dz});
          if (it == cells_.end()) continue;
          for (std::size_t j : it->second) {
            if (j == i) continue;
            double d2 = 0;
            for (int c = 0; c < 3; ++c) {
              const double d = double(points_[i][c]) - points_[j][c];
              d2 += d * d;
            }
            f(j, d2);
          }
        }
      }
    }
  }

 private:
  using Key = std::tuple<std::int64_t, std::int64_t, std::int64_t>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return static_cast<std::size_t>(std::get<0>(k) * 73856093LL ^ std::get<1>(k) * 19349663LL ^
                                      std::get<2>(k) * 83492791LL);
    }
  };
  Key keyOf(const std::array<float, 3>& p) const {
    return Key{static_cast<std::int64_t>(std::floor(p[0] / cell_)),
               static_cast<std::int64_t>(std::floor(p[1] / cell_)),
               static_cast<std::int64_t>(std::floor(p[2] / cell_))};
  }
  const std::vector<std::array<float, 3>>& points_;
  double cell_;
  std::unordered_map<Key, std::vector<std::size_t>, KeyHash> cells_;
};

bool inside(const Footprint& poly, double x, double y) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const auto& a = poly[i];
    const auto& b = poly[j];
    if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) {
      in = !in;
    }
  }
  return in;
}

}  // namespace

std::vector<std::vector<std::size_t>> euclideanClusters(
    const std::vector<std::array<float, 3>>& points, double tolerance, std::size_t min_points) {
  const std::size_t n = points.size();
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  const CellGrid grid(points, tolerance);
  const double t2 = tolerance * tolerance;
  for (std::size_t i = 0; i < n; ++i) {
    grid.forEachNear(i, [&](std::size_t j, double d2) {
      if (j < i || d2 > t2) return;
      const std::size_t a = findRoot(parent, i), b = findRoot(parent, j);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    });
  }
  std::unordered_map<std::size_t, std::size_t> cluster_of_root;
  std::vector<std::vector<std::size_t>> clusters;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t r = findRoot(parent, i);
    auto [it, fresh] = cluster_of_root.emplace(r, clusters.size());
    if (fresh) clusters.emplace_back();
    clusters[it->second].push_back(i);
  }
  clusters.erase(std::remove_if(clusters.begin(), clusters.end(),
                                [&](const auto& c) { return c.size() < min_points; }),
                 clusters.end());
  return clusters;
}

double medianNeighbourDistance(const std::vector<std::array<float, 3>>& points) {
  const std::size_t n = points.size();
  if (n < 2) return 0;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (const auto& p : points) {
    for (int c = 0; c < 3; ++c)
      lo[c] = std::min<double>(lo[c], p[c]), hi[c] = std::max<double>(hi[c], p[c]);
  }
  // Start from the spacing of n points spread over the footprint; double it until more than half
  // of the points have a neighbour within it (their nearest distances are then exact).
  double h = std::max(1e-6, std::sqrt((hi[0] - lo[0]) * (hi[1] - lo[1]) / n));
  for (int round = 0; round < 64; ++round, h *= 2) {
    const CellGrid grid(points, h);
    std::vector<double> nearest(n, INFINITY);
    for (std::size_t i = 0; i < n; ++i) {
      double best = INFINITY;
      grid.forEachNear(i, [&](std::size_t, double d2) { best = std::min(best, d2); });
      if (std::sqrt(best) <= h) nearest[i] = std::sqrt(best);  // exact within h
    }
    std::nth_element(nearest.begin(), nearest.begin() + n / 2, nearest.end());
    if (std::isfinite(nearest[n / 2])) return nearest[n / 2];
  }
  return INFINITY;  // not reached for finite points
}

Footprint convexHull(std::vector<std::array<double, 2>> p) {
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  const auto cross = [](const std::array<double, 2>& o, const std::array<double, 2>& a,
                        const std::array<double, 2>& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  Footprint hull(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
    hull[k++] = p[i];
  }
  hull.resize(k - 1);
  return hull;
}

double footprintIou(const Footprint& a, const Footprint& b, double cell) {
  if (a.size() < 3 || b.size() < 3) return 0;
  Box ba, bb;
  for (const auto& p : a) ba.add(p);
  for (const auto& p : b) bb.add(p);
  Box u{std::min(ba.x0, bb.x0), std::min(ba.y0, bb.y0), std::max(ba.x1, bb.x1),
        std::max(ba.y1, bb.y1)};
  // Disjoint boxes: nothing in common.
  if (ba.x1 < bb.x0 || bb.x1 < ba.x0 || ba.y1 < bb.y0 || bb.y1 < ba.y0) return 0;
  std::size_t both = 0, either = 0;
  const auto nx = static_cast<std::int64_t>(std::ceil((u.x1 - u.x0) / cell));
  const auto ny = static_cast<std::int64_t>(std::ceil((u.y1 - u.y0) / cell));
  for (std::int64_t j = 0; j < ny; ++j) {
    const double y = u.y0 + (j + 0.5) * cell;
    for (std::int64_t i = 0; i < nx; ++i) {
      const double x = u.x0 + (i + 0.5) * cell;
      const bool ia = x >= ba.x0 && x <= ba.x1 && y >= ba.y0 && y <= ba.y1 && inside(a, x, y);
      const bool ib = x >= bb.x0 && x <= bb.x1 && y >= bb.y0 && y <= bb.y1 && inside(b, x, y);
      both += ia && ib;
      either += ia || ib;
    }
  }
  return either ? double(both) / either : 0.0;
}

namespace {

// Greedy one-to-one matching of (iou, truth, predicted) pairs at iou >= match_iou, best first.
void matchPairs(std::vector<std::tuple<double, std::size_t, std::size_t>> pairs, double match_iou,
                ObjectScores* s) {
  std::sort(pairs.begin(), pairs.end(),
            [](const auto& a, const auto& b) { return std::get<0>(a) > std::get<0>(b); });
  std::vector<char> true_used(s->true_objects, 0), pred_used(s->predicted, 0);
  double iou_sum = 0;
  for (const auto& [iou, t, p] : pairs) {
    if (iou < match_iou || true_used[t] || pred_used[p]) continue;
    true_used[t] = pred_used[p] = 1;
    s->matches.emplace_back(t, p);
    ++s->matched;
    iou_sum += iou;
  }
  s->precision = s->predicted ? double(s->matched) / s->predicted : 0.0;
  s->recall = s->true_objects ? double(s->matched) / s->true_objects : 0.0;
  s->f1 = s->precision + s->recall > 0 ? 2 * s->precision * s->recall / (s->precision + s->recall)
                                       : 0.0;
  s->mean_matched_iou = s->matched ? iou_sum / s->matched : 0.0;
}

}  // namespace

ObjectScores scoreRasterObjects(const std::vector<int>& predicted, const std::vector<int>& truth,
                                std::size_t min_cells, double match_iou) {
  int max_p = 0, max_t = 0;
  for (int v : predicted) max_p = std::max(max_p, v);
  for (int v : truth) max_t = std::max(max_t, v);
  std::vector<std::size_t> area_p(max_p + 1, 0), area_t(max_t + 1, 0);
  std::map<std::pair<int, int>, std::size_t> overlap;
  for (std::size_t i = 0; i < predicted.size() && i < truth.size(); ++i) {
    ++area_p[predicted[i]];
    ++area_t[truth[i]];
    if (predicted[i] > 0 && truth[i] > 0) ++overlap[{predicted[i], truth[i]}];
  }
  // Predicted objects kept (>= min_cells), renumbered 0..; true objects 0.. as labelled.
  std::vector<int> kept(max_p + 1, -1);
  ObjectScores s;
  for (int p = 1; p <= max_p; ++p) {
    if (area_p[p] < min_cells || area_p[p] == 0) continue;
    kept[p] = static_cast<int>(s.predicted++);
    s.predicted_labels.push_back(p);
  }
  std::vector<int> true_index(max_t + 1, -1);
  for (int t = 1; t <= max_t; ++t) {
    if (area_t[t] == 0) continue;
    true_index[t] = static_cast<int>(s.true_objects++);
    s.true_labels.push_back(t);
  }
  s.best_iou.assign(s.true_objects, 0.0);
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (const auto& [key, inter] : overlap) {
    const auto [p, t] = key;
    if (kept[p] < 0) continue;
    const double iou = double(inter) / double(area_p[p] + area_t[t] - inter);
    const auto ti = static_cast<std::size_t>(true_index[t]);
    s.best_iou[ti] = std::max(s.best_iou[ti], iou);
    pairs.emplace_back(iou, ti, static_cast<std::size_t>(kept[p]));
  }
  matchPairs(std::move(pairs), match_iou, &s);
  return s;
}

ObjectScores scoreObjects(const std::vector<std::array<float, 3>>& points,
                          const std::vector<Footprint>& truth, const ObjectScoreOptions& o) {
  return scoreGroupedPoints(points, euclideanClusters(points, o.tolerance, o.min_points), truth, o);
}

ObjectScores scoreGroupedPoints(const std::vector<std::array<float, 3>>& points,
                                const std::vector<std::vector<std::size_t>>& groups,
                                const std::vector<Footprint>& truth, const ObjectScoreOptions& o) {
  ObjectScores s;
  s.true_objects = truth.size();
  for (const auto& cluster : groups) {
    if (cluster.size() < o.min_points) continue;
    std::vector<std::array<double, 2>> xy;
    xy.reserve(cluster.size());
    for (std::size_t i : cluster) xy.push_back({points.at(i)[0], points.at(i)[1]});
    s.predicted_footprints.push_back(convexHull(std::move(xy)));
  }
  s.predicted = s.predicted_footprints.size();
  // Every overlapping pair, best IoU first; each object matches once.
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  s.best_iou.assign(truth.size(), 0.0);
  for (std::size_t t = 0; t < truth.size(); ++t) {
    for (std::size_t p = 0; p < s.predicted; ++p) {
      const double iou = footprintIou(truth[t], s.predicted_footprints[p], o.cell);
      if (iou <= 0) continue;
      s.best_iou[t] = std::max(s.best_iou[t], iou);
      if (iou >= o.match_iou) pairs.emplace_back(iou, t, p);
    }
  }
  matchPairs(std::move(pairs), o.match_iou, &s);
  return s;
}

}  // namespace eval
}  // namespace sadsplat
