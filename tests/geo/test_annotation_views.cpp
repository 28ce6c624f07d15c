// Which photos to annotate (geo/annotation_views.h): on a flat square of points seen by nadir
// views of known footprints, the greedy picks, their shares and the errors, worked out by hand.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/annotation_views.h"

namespace sadsplat {
namespace {

// A camera at (x, y, h) looking straight down (R = diag(1, -1, -1)) that sees |X - x| < h and
// |Y - y| < h on the ground.
io::PinholeCamera lookingDownFrom(double x, double y, double h) {
  io::PinholeCamera c;
  c.width = c.height = 100;
  c.fx = c.fy = 50;
  c.cx = c.cy = 50;
  c.qvec = {0, 1, 0, 0};
  c.tvec = {-x, y, h};
  return c;
}

// Points at (i + 0.5, j + 0.5), i, j < 40. With 39 cells along the side the cells are 1 m
// from x = 0.5 (the 1st percentile) to 39.5 (the 99th), the last column and row of points falling
// into the 39th: 39 x 39 = 1521 footprint cells. Views: 0 "centre" sees x, y in [10, 30]
// (20 x 20 = 400 cells), 1-4 the quadrants sw (400 cells), se, nw (19 x 20 = 380 each), ne
// (19 x 19 = 361), 5 a test view that sees everything.
io::Scene square() {
  io::Scene s;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 40; ++j) {
      io::ScenePoint p;
      p.xyz = {i + 0.5f, j + 0.5f, 0.f};
      s.points.push_back(p);
    }
  }
  const double centres[6][3] = {{20, 20, 10}, {10, 10, 10}, {30, 10, 10},
                                {10, 30, 10}, {30, 30, 10}, {20, 20, 20}};
  const char* names[6] = {"centre", "sw", "se", "nw", "ne", "test"};
  for (int v = 0; v < 6; ++v) {
    io::View view;
    view.name = names[v];
    view.camera = lookingDownFrom(centres[v][0], centres[v][1], centres[v][2]);
    view.train = v < 5;
    view.test = v == 5;
    s.views.push_back(view);
  }
  return s;
}

TEST(AnnotationViews, PicksTheViewsThatAddTheMostGroundInTurn) {
  geo::AnnotationViewOptions o;
  o.cells = 39;
  const geo::AnnotationViews c = geo::chooseAnnotationViews(square(), o, "<test>");
  EXPECT_EQ(c.footprint_cells, 1521);
  EXPECT_NEAR(c.cell_size, 1.0, 1e-9);
  EXPECT_NEAR(c.all_share, 1.0, 1e-12);  // the four quadrants; the test view does not count
  // centre and sw see 400 (tie: the lower index); then sw adds 300, se and nw 280, ne 261;
  // then se adds 280 and wins the tie with nw.
  ASSERT_EQ(c.picked, (std::vector<int>{0, 1, 2}));
  EXPECT_NEAR(c.own_share[0], 400 / 1521.0, 1e-12);
  EXPECT_NEAR(c.own_share[2], 380 / 1521.0, 1e-12);
  EXPECT_NEAR(c.cumulative_share[0], 400 / 1521.0, 1e-12);
  EXPECT_NEAR(c.cumulative_share[1], 700 / 1521.0, 1e-12);
  EXPECT_NEAR(c.cumulative_share[2], 980 / 1521.0, 1e-12);
  EXPECT_TRUE(c.kept.empty());
}

TEST(AnnotationViews, StopsWhenNoViewAddsGroundAndNeverPicksATestView) {
  geo::AnnotationViewOptions o;
  o.cells = 39;
  o.count = 6;
  const geo::AnnotationViews c = geo::chooseAnnotationViews(square(), o, "<test>");
  ASSERT_EQ(c.picked, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_NEAR(c.cumulative_share.back(), 1.0, 1e-12);
}

TEST(AnnotationViews, KeptLabelledViewsCountAsPickedFirst) {
  io::Scene s = square();
  s.views[4].labelled = true;  // ne, 361 cells
  geo::AnnotationViewOptions o;
  o.cells = 39;
  o.count = 1;
  geo::AnnotationViews c = geo::chooseAnnotationViews(s, o, "<test>");
  EXPECT_EQ(c.picked, std::vector<int>{0});  // not kept: labels play no part
  o.keep_labelled = true;
  c = geo::chooseAnnotationViews(s, o, "<test>");
  EXPECT_EQ(c.kept, std::vector<int>{4});
  EXPECT_NEAR(c.kept_share, 361 / 1521.0, 1e-12);
  // centre now adds 300 (100 of its cells are ne's), sw 400
  ASSERT_EQ(c.picked, std::vector<int>{1});
  EXPECT_NEAR(c.cumulative_share[0], 761 / 1521.0, 1e-12);
}

TEST(AnnotationViews, BadScenesAndOptionsAreErrorsNamingTheField) {
  geo::AnnotationViewOptions o;
  o.count = 0;
  try {
    geo::chooseAnnotationViews(square(), o, "s.cache");
    FAIL() << "count 0 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("count"), std::string::npos) << e.what();
  }
  o.count = 3;
  o.cells = 1;
  EXPECT_THROW(geo::chooseAnnotationViews(square(), o, "s.cache"), Error);
  o.cells = 48;
  io::Scene s = square();
  s.points.clear();
  try {
    geo::chooseAnnotationViews(s, o, "s.cache");
    FAIL() << "a scene without points accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("s.cache"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("points"), std::string::npos) << e.what();
  }
  s = square();
  for (io::View& v : s.views) v.train = false;
  EXPECT_THROW(geo::chooseAnnotationViews(s, o, "s.cache"), Error);
}

}  // namespace
}  // namespace sadsplat
