#include "sadsplat/geo/block_partition.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace geo {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Edges of `cells` intervals: even between lo and hi inside, infinite outside.
std::vector<double> gridEdges(int cells, double lo, double hi) {
  std::vector<double> edges(cells + 1);
  for (int i = 0; i <= cells; ++i) edges[i] = lo + (hi - lo) * i / cells;
  edges.front() = -kInf;
  edges.back() = kInf;
  return edges;
}

// The interval [edges[i], edges[i+1]) grown by `grow` on each finite side.
std::array<double, 2> grownInterval(const std::vector<double>& edges, int i, double grow) {
  return {std::isfinite(edges[i]) ? edges[i] - grow : -kInf,
          std::isfinite(edges[i + 1]) ? edges[i + 1] + grow : kInf};
}

// The cell index of x among the edges (the last i with edges[i] <= x).
int intervalOf(const std::vector<double>& edges, double x) {
  const auto it = std::upper_bound(edges.begin() + 1, edges.end() - 1, x);
  return static_cast<int>(it - edges.begin()) - 1;
}

nlohmann::json rectJson(const GroundRect& r) {
  // JSON has no infinity: an unbounded side is null.
  const auto side = [](double x) {
    return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
  };
  return {{"e0", side(r.e0)}, {"e1", side(r.e1)}, {"n0", side(r.n0)}, {"n1", side(r.n1)}};
}

}  // namespace

void BlockOptions::check(const std::string& origin) const {
  if (blocks < 1 || blocks > 4096)
    throw Error(origin, "blocks", "1 .. 4096", std::to_string(blocks));
  if (!(overlap >= 0 && overlap <= 1))
    throw Error(origin, "block overlap", "a share of the cell size in 0 .. 1",
                std::to_string(overlap));
  if (!(view_share > 0 && view_share <= 1))
    throw Error(origin, "block view share", "a share in (0, 1]", std::to_string(view_share));
  if (!(labelled_view_share > 0 && labelled_view_share <= 1))
    throw Error(origin, "block labelled view share", "a share in (0, 1]",
                std::to_string(labelled_view_share));
}

int Block::labelledViews(const io::Scene& scene) const {
  int n = 0;
  for (int v : views) n += scene.views[v].labelled ? 1 : 0;
  return n;
}

int BlockPartition::blockAt(double e, double n) const {
  return intervalOf(n_edges, n) * columns + intervalOf(e_edges, e);
}

int BlockPartition::blockOf(const std::array<double, 3>& p) const {
  const auto local = ground.toLocal(p);
  return blockAt(local[0], local[1]);
}

std::vector<int> BlockPartition::blocksOf(const float* xyz, std::size_t count) const {
  std::vector<int> out(count);
  for (std::size_t i = 0; i < count; ++i)
    out[i] = blockOf({xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]});
  return out;
}

std::string BlockPartition::toJson(const io::Scene& scene) const {
  nlohmann::json j;
  j["rows"] = rows;
  j["columns"] = columns;
  j["ground_from_scene"] = ground.scene_to_local;
  nlohmann::json list = nlohmann::json::array();
  for (const Block& b : blocks) {
    nlohmann::json views = nlohmann::json::array();
    for (std::size_t i = 0; i < b.views.size(); ++i) {
      const io::View& v = scene.views[b.views[i]];
      views.push_back({{"name", v.name}, {"share", b.shares[i]}, {"labelled", v.labelled}});
    }
    list.push_back({{"index", b.index},
                    {"row", b.row},
                    {"column", b.column},
                    {"cell", rectJson(b.cell)},
                    {"grown", rectJson(b.grown)},
                    {"points", b.points.size()},
                    {"views", views}});
  }
  j["blocks"] = list;
  nlohmann::json views = nlohmann::json::array();
  for (std::size_t v = 0; v < scene.views.size(); ++v) {
    views.push_back({{"name", scene.views[v].name},
                     {"train", scene.views[v].train},
                     {"test", scene.views[v].test},
                     {"cell_shares", view_cell_shares[v]}});
  }
  j["views"] = views;
  return j.dump(2) + "\n";
}

std::array<int, 2> gridShape(int blocks, double width, double height) {
  std::array<int, 2> best{1, blocks};
  double best_cost = kInf;
  for (int rows = 1; rows <= blocks; ++rows) {
    if (blocks % rows != 0) continue;
    const int columns = blocks / rows;
    // How far the cells are from square: |log(cell width / cell height)|.
    const double cost =
        std::abs(std::log((std::max(width, 1e-9) / columns) / (std::max(height, 1e-9) / rows)));
    if (cost < best_cost - 1e-12) {
      best_cost = cost;
      best = {rows, columns};
    }
  }
  return best;
}

BlockPartition partitionScene(const io::Scene& scene, const BlockOptions& options,
                              const std::string& origin) {
  options.check(origin);
  if (scene.points.empty())
    throw Error(origin, "points", "sparse points to place the blocks", "none");
  BlockPartition p;
  const GroundPoints ground = groundPoints(scene);
  p.ground = ground.frame;
  const std::size_t np = scene.points.size();
  const std::vector<double>&es = ground.e, &ns = ground.n;
  const double e_lo = ground.e0, e_hi = ground.e1, n_lo = ground.n0, n_hi = ground.n1;
  const auto shape = gridShape(options.blocks, e_hi - e_lo, n_hi - n_lo);
  p.rows = shape[0];
  p.columns = shape[1];
  p.e_edges = gridEdges(p.columns, e_lo, e_hi);
  p.n_edges = gridEdges(p.rows, n_lo, n_hi);
  std::vector<std::vector<int>> grown_of(np);  // per point: the blocks whose grown cell holds it
  const double grow_e = options.overlap * (e_hi - e_lo) / p.columns;
  const double grow_n = options.overlap * (n_hi - n_lo) / p.rows;
  for (int r = 0; r < p.rows; ++r) {
    for (int c = 0; c < p.columns; ++c) {
      Block b;
      b.index = r * p.columns + c;
      b.row = r;
      b.column = c;
      b.cell = {p.e_edges[c], p.e_edges[c + 1], p.n_edges[r], p.n_edges[r + 1]};
      const auto ge = grownInterval(p.e_edges, c, grow_e);
      const auto gn = grownInterval(p.n_edges, r, grow_n);
      b.grown = {ge[0], ge[1], gn[0], gn[1]};
      for (std::size_t i = 0; i < np; ++i) {
        if (!b.grown.contains(es[i], ns[i])) continue;
        b.points.push_back(static_cast<int>(i));
        grown_of[i].push_back(b.index);
      }
      p.blocks.push_back(std::move(b));
    }
  }
  // Which points each view sees, and the share of them in each block's cell and grown cell.
  std::vector<int> cell_of(np);
  for (std::size_t i = 0; i < np; ++i) cell_of[i] = p.blockAt(es[i], ns[i]);
  bool any_train = false;
  p.view_cell_shares.resize(scene.views.size());
  for (std::size_t v = 0; v < scene.views.size(); ++v) {
    const io::View& view = scene.views[v];
    any_train = any_train || view.train;
    const io::PointProjector camera(view.camera);
    std::vector<int> in_block(p.blocks.size(), 0), in_cell(p.blocks.size(), 0);
    int seen = 0;
    double u = 0, w = 0, z = 0;
    for (std::size_t i = 0; i < np; ++i) {
      if (!camera.project(scene.points[i].xyz, &u, &w, &z)) continue;
      ++seen;
      ++in_cell[cell_of[i]];
      for (int b : grown_of[i]) ++in_block[b];
    }
    if (seen == 0) continue;  // sees no point: no block can use it
    for (int n : in_cell) p.view_cell_shares[v].push_back(static_cast<double>(n) / seen);
    if (!view.train) continue;
    const double need = view.labelled ? options.labelled_view_share : options.view_share;
    int best = 0;
    bool placed = false;
    for (Block& b : p.blocks) {
      const double share = static_cast<double>(in_block[b.index]) / seen;
      if (in_block[b.index] > in_block[best]) best = b.index;
      if (share >= need) {
        b.views.push_back(static_cast<int>(v));
        b.shares.push_back(share);
        placed = true;
      }
    }
    if (!placed) {
      p.blocks[best].views.push_back(static_cast<int>(v));
      p.blocks[best].shares.push_back(static_cast<double>(in_block[best]) / seen);
    }
  }
  if (!any_train) throw Error(origin, "split", "at least one training view", "none");
  // Views were visited in scene order: each block's list is ascending.
  return p;
}

io::Scene blockScene(const io::Scene& scene, const Block& block) {
  io::Scene s;
  s.source = scene.source;
  s.classes = scene.classes;
  s.georeference = scene.georeference;
  s.views.reserve(block.views.size());
  for (int v : block.views) s.views.push_back(scene.views[v]);
  s.points.reserve(block.points.size());
  for (int i : block.points) s.points.push_back(scene.points[i]);
  return s;
}

}  // namespace geo
}  // namespace sadsplat
