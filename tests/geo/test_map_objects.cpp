// Objects on a class map (geo/map_objects.h): regions cut where the surface model steps, slivers
// merged into their neighbours; and their polygons in a GeoPackage read back by OGR's ogrinfo.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/eval/object_scores.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/geo/map_objects.h"
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/geo/vector_files.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

TEST(MapObjects, PlainRegionsAreEightConnectedAndScoredByIou) {
  // 10 x 6 cells: two predicted regions (one touching only diagonally joins), a speck.
  const int W = 10, H = 6;
  std::vector<std::uint8_t> mask(W * H, 0);
  const auto set = [&](int x, int y) { mask[y * W + x] = 1; };
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 3; ++x) set(x, y);  // region A: 3 x 3
  }
  set(3, 3);  // diagonal neighbour of A's corner (2, 2): joins A
  for (int y = 0; y < 4; ++y) {
    for (int x = 6; x < 9; ++x) set(x, y);  // region B: 3 x 4
  }
  set(5, 5);  // a speck
  geo::MapObjectOptions plain;
  plain.max_step = 0;
  const std::vector<int> labels = geo::mapObjects(mask, {}, W, H, plain);
  EXPECT_EQ(labels[0], 1);
  EXPECT_EQ(labels[3 * W + 3], 1);
  EXPECT_EQ(labels[6], 2);
  EXPECT_EQ(labels[5 * W + 5], 3);
  EXPECT_EQ(labels[9], 0);
  // Truth: A's 3 x 3 exactly (IoU 9 / 10), and B's left two columns (IoU 8 / 12 = 0.67), and a
  // building nothing found.
  std::vector<int> truth(W * H, 0);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 3; ++x) truth[y * W + x] = 1;
  }
  for (int y = 0; y < 4; ++y) {
    for (int x = 6; x < 8; ++x) truth[y * W + x] = 2;
  }
  truth[5 * W + 0] = 3;
  const eval::ObjectScores s = eval::scoreRasterObjects(labels, truth, 2);
  EXPECT_EQ(s.predicted, 2u);  // the speck is under 2 cells
  EXPECT_EQ(s.true_objects, 3u);
  EXPECT_EQ(s.matched, 2u);
  EXPECT_NEAR(s.precision, 1.0, 1e-12);
  EXPECT_NEAR(s.recall, 2.0 / 3, 1e-12);
  EXPECT_NEAR(s.mean_matched_iou, (0.9 + 8.0 / 12) / 2, 1e-12);
  EXPECT_NEAR(s.best_iou[2], 0.0, 1e-12);
  // The pairs, by the objects' labels: A with truth 1, B with truth 2; the speck is not kept.
  EXPECT_EQ(s.true_labels, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(s.predicted_labels, (std::vector<int>{1, 2}));
  ASSERT_EQ(s.matches.size(), 2u);
  for (const auto& [t, p] : s.matches) EXPECT_EQ(s.true_labels[t], s.predicted_labels[p]);
}

// 12 x 5 cells of one class: a roof at 10 m (x 0-4), a column bridging the gap at 0.3 m (x 5),
// a roof at 16 m (x 6-11) whose last column slopes down by 0.5 m a cell (x 9-11: a gable).
struct TwoRoofs {
  static constexpr int W = 12, H = 5;
  std::vector<std::uint8_t> mask = std::vector<std::uint8_t>(W * H, 1);
  std::vector<float> heights = std::vector<float>(W * H, 0.f);
  TwoRoofs() {
    for (int y = 0; y < H; ++y) {
      for (int x = 0; x < W; ++x) {
        heights[y * W + x] = x < 5 ? 10.f : x == 5 ? 0.3f : 16.f - 0.5f * std::max(0, x - 8);
      }
    }
  }
};

TEST(MapObjects, HeightStepsCutARegionIntoObjects) {
  const TwoRoofs m;
  geo::MapObjectOptions o;
  o.max_step = 1.5;
  std::vector<int> labels = geo::mapObjects(m.mask, m.heights, m.W, m.H, o);
  // Row-major order of the first cell: the left roof, the bridge, the right roof with its slope
  // (steps of 0.5 m join).
  for (int y = 0; y < m.H; ++y) {
    for (int x = 0; x < m.W; ++x) {
      EXPECT_EQ(labels[y * m.W + x], x < 5 ? 1 : x == 5 ? 2 : 3) << x << "," << y;
    }
  }
  // A step of 10 m joins the bridge to the left roof (9.7 m apart), not to the right (15.7 m).
  o.max_step = 10;
  labels = geo::mapObjects(m.mask, m.heights, m.W, m.H, o);
  EXPECT_EQ(labels[0], 1);
  EXPECT_EQ(labels[5], 1);
  EXPECT_EQ(labels[6], 2);
  // No step: one region; a step of 0.4 m also cuts the gable (0.5 m a cell) apart.
  o.max_step = 0;
  labels = geo::mapObjects(m.mask, m.heights, m.W, m.H, o);
  for (int l : labels) EXPECT_EQ(l, 1);
  o.max_step = 0.4;
  labels = geo::mapObjects(m.mask, m.heights, m.W, m.H, o);
  EXPECT_EQ(labels[m.W - 1], 6);  // left, bridge, right's flat part, then one per sloped column
}

TEST(MapObjects, SliversMergeIntoTheNeighbourTheyBorderMost) {
  TwoRoofs m;
  geo::MapObjectOptions o;
  o.max_step = 1.5;
  o.min_cells = 6;  // the bridge (5 cells) is a sliver; the roofs (25, 30) are not
  std::vector<int> labels = geo::mapObjects(m.mask, m.heights, m.W, m.H, o);
  // The bridge borders both roofs alike (13 cell pairs each): it joins the larger, the right.
  for (int y = 0; y < m.H; ++y) {
    for (int x = 0; x < m.W; ++x) EXPECT_EQ(labels[y * m.W + x], x < 5 ? 1 : 2) << x;
  }
  // With the right roof's first column out of the class, the bridge borders the left roof only.
  for (int y = 0; y < m.H; ++y) m.mask[y * m.W + 6] = 0;
  labels = geo::mapObjects(m.mask, m.heights, m.W, m.H, o);
  for (int y = 0; y < m.H; ++y) {
    EXPECT_EQ(labels[y * m.W + 5], 1);  // the bridge joined the left roof, its only neighbour
    EXPECT_EQ(labels[y * m.W + 6], 0);
    EXPECT_EQ(labels[y * m.W + 7], 2);
  }
  // A sliver with no neighbour stays an object of its own; merging never crosses the mask.
  std::vector<std::uint8_t> speck(m.mask.size(), 0);
  speck[2 * m.W + 2] = 1;
  labels = geo::mapObjects(speck, m.heights, m.W, m.H, o);
  EXPECT_EQ(labels[2 * m.W + 2], 1);
}

TEST(MapObjects, CellsWithoutHeightJoinOnlyEachOther) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<std::uint8_t> mask(4, 1);
  const std::vector<float> heights = {5.f, nan, nan, 5.f};
  geo::MapObjectOptions o;
  const std::vector<int> labels = geo::mapObjects(mask, heights, 4, 1, o);
  EXPECT_EQ(labels, (std::vector<int>{1, 2, 2, 3}));
}

TEST(MapObjects, BadInputIsAnError) {
  geo::MapObjectOptions o;
  EXPECT_THROW(
      geo::mapObjects(std::vector<std::uint8_t>(5, 1), std::vector<float>(5, 0.f), 2, 2, o), Error);
  EXPECT_THROW(geo::mapObjects(std::vector<std::uint8_t>(4, 1), {}, 2, 2, o), Error);
  o.max_step = -1;
  EXPECT_THROW(
      geo::mapObjects(std::vector<std::uint8_t>(4, 1), std::vector<float>(4, 0.f), 2, 2, o), Error);
  o.max_step = 0;  // no heights needed
  EXPECT_NO_THROW(geo::mapObjects(std::vector<std::uint8_t>(4, 1), {}, 2, 2, o));
}

// The trim (ortho --trim): a roof object of 6 x 4 cells whose Gaussians' hull covers only its
// left 4 x 4 cells: the right two columns lie outside; an object with a degenerate hull (two
// corners) keeps its cells; an object without a polygon is an error.
TEST(MapObjects, CellsOutsideTheirObjectsHullAreFound) {
  const int w = 8, h = 6;
  std::vector<int> labels(w * h, 0);
  for (int y = 1; y < 5; ++y) {
    for (int x = 1; x < 7; ++x) labels[y * w + x] = 1;
  }
  labels[0] = 2;  // object 2: one cell in the corner
  const std::vector<std::vector<std::array<double, 2>>> hulls = {
      {{1, 1}, {5, 1}, {5, 5}, {1, 5}},  // cells x 1..4 (centres 1.5 .. 4.5) inside
      {{0, 0}, {1, 1}}};                 // a line: no area, every cell kept
  const std::vector<std::size_t> outside = geo::cellsOutsideHulls(labels, w, hulls);
  std::vector<std::size_t> expected;
  for (int y = 1; y < 5; ++y) {
    for (int x = 5; x < 7; ++x) expected.push_back(static_cast<std::size_t>(y * w + x));
  }
  EXPECT_EQ(outside, expected);
  // The other orientation of the same polygon gives the same cells.
  const std::vector<std::vector<std::array<double, 2>>> reversed = {
      {{1, 5}, {5, 5}, {5, 1}, {1, 1}}, {}};
  EXPECT_EQ(geo::cellsOutsideHulls(labels, w, reversed), expected);
  EXPECT_THROW(geo::cellsOutsideHulls(labels, w, {hulls[0]}), Error);
}

// Trimmed cells take the class most of the allowed, covered, untrimmed cells around them have;
// a cell with none around it is returned unchanged.
TEST(MapObjects, TrimmedCellsTakeTheClassAroundThem) {
  const int w = 7, h = 3;
  // Row-major: class 0 (building) in x 0..2, road (1) x 3..4 on rows 0-1, grass (2) x 3..6 on
  // row 2 and x 5..6 above; a car (3) at (6, 0) that may not be chosen.
  std::vector<std::uint8_t> classes = {0, 0, 0, 1, 1, 2, 3,  //
                                       0, 0, 0, 1, 1, 2, 2,  //
                                       0, 0, 0, 2, 2, 2, 2};
  std::vector<std::uint8_t> covered(w * h, 1);
  covered[7 + 4] = 0;  // an uncovered road cell does not vote
  const std::vector<std::uint8_t> allowed = {0, 1, 1, 0};
  // (2, 0) and (2, 1): radius 1 sees roads (3, 0), (3, 1) and grass (3, 2): road wins 2 to 1;
  // (0, 0): only building cells (not allowed) around it: left unchanged.
  const std::vector<std::size_t> cells = {2, 7 + 2, 0};
  const std::vector<std::size_t> alone =
      geo::takeClassAround(classes, covered, w, h, cells, allowed, 1);
  EXPECT_EQ(alone, std::vector<std::size_t>{0});
  EXPECT_EQ(classes[2], 1);
  EXPECT_EQ(classes[7 + 2], 1);
  EXPECT_EQ(classes[0], 0);
  // A wider window reaches the grass: (2, 1) at radius 3 sees road (3, 0), (3, 1), (4, 0) and
  // grass (3, 2), (4, 2), (5, 0..2): grass 5 to 3 (the uncovered road cell not counted).
  std::vector<std::uint8_t> wide = {0, 0, 0, 1, 1, 2, 3,  //
                                    0, 0, 0, 1, 1, 2, 2,  //
                                    0, 0, 0, 2, 2, 2, 2};
  geo::takeClassAround(wide, covered, w, h, {7 + 2}, allowed, 3);
  EXPECT_EQ(wide[7 + 2], 2);
  EXPECT_THROW(geo::takeClassAround(wide, std::vector<std::uint8_t>(3, 1), w, h, {}, allowed, 1),
               Error);
}

// The objects' polygons as OGR reads them: one feature per object with its class, height and
// area (cells of 0.5 m, so a 5 x 5 roof is 6.25 m^2).
TEST(MapObjects, PolygonsInAGeoPackageCarryTheObjects) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  if (test::runCommand("ogrinfo --version") != 0) GTEST_SKIP() << "no ogrinfo (gdal-bin)";
  const TwoRoofs m;
  geo::MapObjectOptions o;
  o.min_cells = 6;
  const std::vector<int> labels = geo::mapObjects(m.mask, m.heights, m.W, m.H, o);
  std::vector<geo::MapObjectAttributes> objects(2);
  objects[0] = {1, 10.0, 9.5};  // its height above the ground known, the other's not
  objects[1] = {1, 16.0};
  test::TempDir dir;
  const std::string path = dir.file("objects.gpkg");
  const geo::MapGrid grid{100.0, 200.0, 0.5, ""};
  EXPECT_EQ(
      geo::writeObjectPolygons(path, labels, m.W, m.H, objects, grid, {"road", "building"}, {}),
      2u);
  std::string out;
  ASSERT_EQ(test::runCommand("ogrinfo -q -sql \"SELECT object_id, class, height_m, "
                             "height_above_ground_m, area_m2 FROM classes ORDER BY object_id\" " +
                                 path,
                             &out),
            0)
      << out;
  EXPECT_NE(out.find("object_id (Integer) = 1"), std::string::npos) << out;
  EXPECT_NE(out.find("area_m2 (Real) = 6.25"), std::string::npos) << out;
  EXPECT_NE(out.find("height_m (Real) = 16"), std::string::npos) << out;
  EXPECT_NE(out.find("area_m2 (Real) = 8.75"), std::string::npos) << out;  // bridge + right
  EXPECT_NE(out.find("height_above_ground_m (Real) = 9.5"), std::string::npos) << out;
  EXPECT_NE(out.find("height_above_ground_m (Real) = (null)"), std::string::npos) << out;
  EXPECT_NE(out.find("class (String) = building"), std::string::npos) << out;
  // A label no object describes is an error naming the file.
  EXPECT_THROW(geo::writeObjectPolygons(path, labels, m.W, m.H, {{1, 10.0}}, grid, {"a", "b"}, {}),
               Error);
}

// Cells of one object joined only at a corner (8-connected) polygonize into a ring that touches
// itself there; the written polygon is OGC-valid as GEOS checks it (SQLite dialect's ST_IsValid),
// with the cells' whole area.
TEST(MapObjects, CornerJoinedCellsGiveValidPolygons) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  if (test::runCommand("ogrinfo --version") != 0) GTEST_SKIP() << "no ogrinfo (gdal-bin)";
  // 4 x 3 cells: a 2 x 2 block and one cell at its lower-right corner's diagonal.
  const int W = 4, H = 3;
  std::vector<std::uint8_t> mask(W * H, 0);
  for (const int k : {0, 1, W, W + 1, 2 * W + 2}) mask[k] = 1;
  geo::MapObjectOptions o;
  o.max_step = 0;
  const std::vector<int> labels = geo::mapObjects(mask, {}, W, H, o);
  ASSERT_EQ(labels[2 * W + 2], 1);  // one object
  test::TempDir dir;
  const std::string path = dir.file("corner.gpkg");
  EXPECT_EQ(geo::writeObjectPolygons(path, labels, W, H, {{0, 1.0}}, {0.0, 3.0, 1.0, ""},
                                     {"building"}, {}),
            1u);
  std::string out;
  ASSERT_EQ(test::runCommand("ogrinfo -q -dialect SQLite -sql \"SELECT ST_IsValid(geom) AS valid, "
                             "ST_Area(geom) AS area FROM classes\" " +
                                 path + " 2>&1",
                             &out),
            0)
      << out;
  EXPECT_NE(out.find("valid (Integer) = 1"), std::string::npos) << out;
  EXPECT_NE(out.find("area (Real) = 5"), std::string::npos) << out;
}

}  // namespace
}  // namespace sadsplat
