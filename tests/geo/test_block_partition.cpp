// The block partition of `sadsplat train --blocks`: cells that hold every point once, grown
// cells, and each block's views chosen by the share of their points in it, as block_partition.h
// states; checked against an independent count on a nadir grid survey made here.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <numeric>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/block_partition.h"

namespace sadsplat {
namespace {

// A camera at (x, y, h) looking straight down (world z up): R = diag(1, -1, -1).
io::PinholeCamera nadirCamera(double x, double y, double h) {
  io::PinholeCamera c;
  c.width = 100;
  c.height = 80;
  c.fx = c.fy = 100;  // footprint: (100 x 80 px) x h / fx, 25 x 20 m at 25 m
  c.cx = 50;
  c.cy = 40;
  c.qvec = {0, 1, 0, 0};
  c.tvec = {-x, y, h};
  return c;
}

// Points on a 61 x 41 grid over [0, 120] x [0, 80] on the ground; 5 x 4 nadir views at 25 m.
io::Scene gridSurvey() {
  io::Scene s;
  for (int i = 0; i <= 60; ++i) {
    for (int j = 0; j <= 40; ++j) {
      io::ScenePoint p;
      p.xyz = {static_cast<float>(2 * i), static_cast<float>(2 * j), 0.f};
      s.points.push_back(p);
    }
  }
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 4; ++j) {
      io::View v;
      v.name = "v" + std::to_string(i) + std::to_string(j);
      v.camera = nadirCamera(12 + 24 * i, 10 + 20 * j, 25);
      v.train = true;
      s.views.push_back(v);
    }
  }
  s.views[7].labelled = true;
  s.views[19].train = false;  // a test view: in no block
  s.views[19].test = true;
  return s;
}

// The share of a view's visible points in a rectangle, counted here without the library.
double shareIn(const io::View& v, const io::Scene& s, const geo::GroundRect& r) {
  const double x0 = -v.camera.tvec[0], y0 = v.camera.tvec[1], h = v.camera.tvec[2];
  int seen = 0, in = 0;
  for (const io::ScenePoint& p : s.points) {
    const double u = v.camera.fx * (p.xyz[0] - x0) / h + v.camera.cx;
    const double w = v.camera.fy * (-(p.xyz[1] - y0)) / h + v.camera.cy;
    if (u < 0 || u >= v.camera.width || w < 0 || w >= v.camera.height) continue;
    ++seen;
    in += r.contains(p.xyz[0], p.xyz[1]) ? 1 : 0;
  }
  return seen ? static_cast<double>(in) / seen : 0;
}

TEST(BlockPartition, GridShapeMakesCellsClosestToSquare) {
  EXPECT_EQ(geo::gridShape(4, 100, 100), (std::array<int, 2>{2, 2}));
  EXPECT_EQ(geo::gridShape(4, 400, 100), (std::array<int, 2>{1, 4}));
  EXPECT_EQ(geo::gridShape(4, 100, 400), (std::array<int, 2>{4, 1}));
  EXPECT_EQ(geo::gridShape(6, 300, 200), (std::array<int, 2>{2, 3}));
  EXPECT_EQ(geo::gridShape(1, 5, 500), (std::array<int, 2>{1, 1}));
  EXPECT_EQ(geo::gridShape(7, 700, 100), (std::array<int, 2>{1, 7}));
}

TEST(BlockPartition, EveryPointLiesInExactlyOneCell) {
  const io::Scene s = gridSurvey();
  geo::BlockOptions o;
  o.blocks = 6;
  const geo::BlockPartition p = geo::partitionScene(s, o, "survey");
  ASSERT_EQ(p.rows * p.columns, 6);
  EXPECT_EQ(p.rows, 2);  // 120 x 80 m: 3 columns of 40 m, 2 rows of 40 m
  EXPECT_EQ(p.columns, 3);
  ASSERT_EQ(p.blocks.size(), 6u);
  std::vector<int> in_cells(6, 0);
  // Also points far outside the sparse points' extent, and on the inner edges.
  std::vector<std::array<double, 3>> probes;
  for (const io::ScenePoint& q : s.points) probes.push_back({q.xyz[0], q.xyz[1], q.xyz[2]});
  probes.push_back({-1e6, 5, 0});
  probes.push_back({1e6, 1e6, 30});
  probes.push_back({p.e_edges[1], p.n_edges[1], 0});
  for (const auto& x : probes) {
    int owners = 0;
    for (const geo::Block& b : p.blocks) owners += b.cell.contains(x[0], x[1]) ? 1 : 0;
    ASSERT_EQ(owners, 1) << x[0] << ", " << x[1];
    const int b = p.blockOf(x);
    EXPECT_TRUE(p.blocks[b].cell.contains(x[0], x[1]));
    if (&x - probes.data() < static_cast<long>(s.points.size())) ++in_cells[b];
  }
  for (int n : in_cells) EXPECT_GT(n, 200);  // cells of ~400 points each
  // A grown cell holds its cell and more, by overlap x cell size on each finite side.
  const geo::Block& middle = p.blocks[1];  // row 0, column 1
  EXPECT_NEAR(middle.grown.e0, middle.cell.e0 - o.overlap * (middle.cell.e1 - middle.cell.e0),
              1e-9);
  EXPECT_EQ(middle.grown.n0, -std::numeric_limits<double>::infinity());
  for (const geo::Block& b : p.blocks) {
    std::size_t in_grown = 0;
    for (const io::ScenePoint& q : s.points) in_grown += b.grown.contains(q.xyz[0], q.xyz[1]);
    EXPECT_EQ(b.points.size(), in_grown) << b.index;
    EXPECT_GT(b.points.size(), static_cast<std::size_t>(in_cells[b.index]));
  }
}

TEST(BlockPartition, ViewsJoinTheBlocksThatHoldTheirShareOfWhatTheySee) {
  const io::Scene s = gridSurvey();
  geo::BlockOptions o;
  o.blocks = 4;
  o.view_share = 0.3;
  o.labelled_view_share = 0.05;
  const geo::BlockPartition p = geo::partitionScene(s, o, "survey");
  std::vector<int> memberships(s.views.size(), 0);
  for (const geo::Block& b : p.blocks) {
    for (std::size_t k = 0; k < b.views.size(); ++k) {
      if (k > 0) EXPECT_LT(b.views[k - 1], b.views[k]);
      ++memberships[b.views[k]];
      EXPECT_NEAR(b.shares[k], shareIn(s.views[b.views[k]], s, b.grown), 1e-12);
    }
  }
  for (std::size_t v = 0; v < s.views.size(); ++v) {
    if (!s.views[v].train) {
      EXPECT_EQ(memberships[v], 0) << "a test view trains no block";
      continue;
    }
    EXPECT_GE(memberships[v], 1) << "every training view trains some block";
    const double need = s.views[v].labelled ? o.labelled_view_share : o.view_share;
    bool any = false;
    for (const geo::Block& b : p.blocks) any = any || shareIn(s.views[v], s, b.grown) >= need;
    for (const geo::Block& b : p.blocks) {
      const bool member = std::find(b.views.begin(), b.views.end(), v) != b.views.end();
      if (any) EXPECT_EQ(member, shareIn(s.views[v], s, b.grown) >= need) << v << " " << b.index;
    }
  }
  // Every view that sees points, test views too, has its shares per cell; they sum to 1.
  ASSERT_EQ(p.view_cell_shares.size(), s.views.size());
  for (const auto& shares : p.view_cell_shares) {
    ASSERT_EQ(shares.size(), 4u);
    EXPECT_NEAR(std::accumulate(shares.begin(), shares.end(), 0.0), 1.0, 1e-12);
  }
  EXPECT_NEAR(p.view_cell_shares[19][p.blockOf({-s.views[19].camera.tvec[0],
                                                s.views[19].camera.tvec[1], 0})],
              *std::max_element(p.view_cell_shares[19].begin(), p.view_cell_shares[19].end()),
              1e-12)
      << "a nadir view's largest share is the cell under it";
  // The labelled view joins more blocks than its share would give an unlabelled one.
  EXPECT_GT(memberships[7], 1);
  const io::Scene block = geo::blockScene(s, p.blocks[0]);
  ASSERT_EQ(block.views.size(), p.blocks[0].views.size());
  EXPECT_EQ(block.views[0].name, s.views[p.blocks[0].views[0]].name);
  EXPECT_EQ(block.points.size(), p.blocks[0].points.size());
  const auto j = nlohmann::json::parse(p.toJson(s));
  EXPECT_EQ(j["blocks"].size(), 4u);
  EXPECT_TRUE(j["blocks"][0]["cell"]["e0"].is_null()) << "an unbounded side is null";
  EXPECT_EQ(j["blocks"][0]["views"].size(), p.blocks[0].views.size());
}

TEST(BlockPartition, BadInputIsAClearError) {
  io::Scene s = gridSurvey();
  geo::BlockOptions o;
  o.blocks = 0;
  EXPECT_THROW(geo::partitionScene(s, o, "survey"), Error);
  o.blocks = 2;
  o.overlap = 1.5;
  EXPECT_THROW(geo::partitionScene(s, o, "survey"), Error);
  o.overlap = 0.2;
  for (io::View& v : s.views) v.train = false;
  EXPECT_THROW(geo::partitionScene(s, o, "survey"), Error);
  s.points.clear();
  try {
    geo::partitionScene(s, o, "survey");
    FAIL() << "no points";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("points"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sadsplat
