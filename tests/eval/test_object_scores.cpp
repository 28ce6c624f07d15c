// Objects of one class against true footprints: Euclidean clusters, convex hulls, footprint IoU
// and the one-to-one matching, on hand-placed points whose answers are known.
#include <gtest/gtest.h>

#include "sadsplat/eval/object_scores.h"

namespace sadsplat {
namespace {

// A grid of points spaced `step` over [x0, x1] x [y0, y1] at height z.
void addRoof(std::vector<std::array<float, 3>>* points, float x0, float y0, float x1, float y1,
             float z, float step = 0.5f) {
  for (float y = y0; y <= y1 + 1e-4f; y += step) {
    for (float x = x0; x <= x1 + 1e-4f; x += step) points->push_back({x, y, z});
  }
}

TEST(ObjectScores, ClustersJoinCentresWithinTheTolerance) {
  std::vector<std::array<float, 3>> p;
  for (int i = 0; i < 10; ++i) p.push_back({0.9f * i, 0, 0});      // a chain 0.9 apart: one cluster
  for (int i = 0; i < 5; ++i) p.push_back({20 + 0.5f * i, 0, 5});  // another, 11.9 m away
  p.push_back({50, 50, 50});                                       // alone
  const auto clusters = eval::euclideanClusters(p, 1.0, 2);
  ASSERT_EQ(clusters.size(), 2u);
  EXPECT_EQ(clusters[0].size(), 10u);
  EXPECT_EQ(clusters[1].size(), 5u);
  EXPECT_EQ(clusters[1].front(), 10u);
  // A tolerance below the chain's spacing breaks it into single points, which min_points drops.
  EXPECT_EQ(eval::euclideanClusters(p, 0.8, 2).size(), 1u);
}

// The spacing of a roof sampled every 2 m (plus a far, lonely point and a close pair) is 2 m,
// whatever the bounding box; a spacing far below the footprint's density estimate is found too.
TEST(ObjectScores, MedianNeighbourDistanceIsTheSamplingSpacing) {
  std::vector<std::array<float, 3>> roof;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 20; ++j) roof.push_back({2.f * i, 2.f * j, 12.f});
  roof.push_back({500.f, 500.f, 0.f});
  roof.push_back({-100.f, 0.f, 0.f});
  roof.push_back({-100.f, 0.3f, 0.f});
  EXPECT_NEAR(eval::medianNeighbourDistance(roof), 2.0, 1e-6);
  std::vector<std::array<float, 3>> dense;
  for (int i = 0; i < 40; ++i) dense.push_back({0.01f * i, 0.f, 0.f});
  dense.push_back({1000.f, 1000.f, 0.f});
  EXPECT_NEAR(eval::medianNeighbourDistance(dense), 0.01, 1e-5);
  EXPECT_EQ(eval::medianNeighbourDistance({{1.f, 2.f, 3.f}}), 0.0);
  // A line (no footprint area: the search starts tiny and widens) of points 100 m apart.
  std::vector<std::array<float, 3>> line;
  for (int i = 0; i < 10; ++i) line.push_back({100.f * i, 0.f, 0.f});
  EXPECT_NEAR(eval::medianNeighbourDistance(line), 100.0, 1e-6);
}

TEST(ObjectScores, HullsAndFootprintIou) {
  const eval::Footprint hull =
      eval::convexHull({{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 0.5}, {0, 0}});
  ASSERT_EQ(hull.size(), 4u);
  // Counter-clockwise: positive shoelace area 4.
  double area = 0;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const auto& a = hull[i];
    const auto& b = hull[(i + 1) % hull.size()];
    area += a[0] * b[1] - b[0] * a[1];
  }
  EXPECT_NEAR(area / 2, 4.0, 1e-12);
  const eval::Footprint square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const eval::Footprint shifted = {{0.5, 0}, {1.5, 0}, {1.5, 1}, {0.5, 1}};
  EXPECT_NEAR(eval::footprintIou(square, shifted, 0.01), 1.0 / 3, 0.01);
  EXPECT_NEAR(eval::footprintIou(square, square, 0.01), 1.0, 1e-9);
  EXPECT_EQ(eval::footprintIou(square, {{5, 5}, {6, 5}, {6, 6}}, 0.01), 0.0);
}

TEST(ObjectScores, MatchesOneToOneAtHalfTheFootprint) {
  const std::vector<eval::Footprint> truth = {{{0, 0}, {10, 0}, {10, 10}, {0, 10}},
                                              {{20, 0}, {30, 0}, {30, 10}, {20, 10}}};
  std::vector<std::array<float, 3>> p;
  addRoof(&p, 0.25f, 0.25f, 9.75f, 9.75f, 8);    // the first roof: hull 9.5 x 9.5, IoU 0.9025
  addRoof(&p, 20.25f, 0.25f, 24.75f, 9.75f, 6);  // half the second: 4.5 x 9.5, IoU 0.4275
  addRoof(&p, 50, 50, 52, 52, 3);                // no building there
  const eval::ObjectScores s = eval::scoreObjects(p, truth, {});
  EXPECT_EQ(s.true_objects, 2u);
  EXPECT_EQ(s.predicted, 3u);
  EXPECT_EQ(s.matched, 1u);
  EXPECT_NEAR(s.precision, 1.0 / 3, 1e-12);
  EXPECT_NEAR(s.recall, 0.5, 1e-12);
  EXPECT_NEAR(s.f1, 0.4, 1e-12);
  ASSERT_EQ(s.best_iou.size(), 2u);
  EXPECT_NEAR(s.best_iou[0], 0.9025, 0.01);
  EXPECT_NEAR(s.best_iou[1], 0.4275, 0.01);
  EXPECT_NEAR(s.mean_matched_iou, 0.9025, 0.01);
  // Two clusters on one building: only one of them matches it.
  std::vector<std::array<float, 3>> split;
  addRoof(&split, 0.25f, 0.25f, 9.75f, 9.75f, 8);
  addRoof(&split, 0.25f, 0.25f, 9.75f, 9.75f, 20);  // the same footprint 12 m higher
  const eval::ObjectScores t = eval::scoreObjects(split, {truth[0]}, {});
  EXPECT_EQ(t.predicted, 2u);
  EXPECT_EQ(t.matched, 1u);
  EXPECT_NEAR(t.precision, 0.5, 1e-12);
}

// Two roofs 0.75 m apart: clustering at 1 m joins them into one object that matches neither;
// grouped by other means (e.g. the map's objects under them) each roof is its own and matches.
TEST(ObjectScores, GroupedPointsAreScoredAsGivenNotClustered) {
  const std::vector<eval::Footprint> truth = {{{0, 0}, {10, 0}, {10, 10}, {0, 10}},
                                              {{10.5, 0}, {20.5, 0}, {20.5, 10}, {10.5, 10}}};
  std::vector<std::array<float, 3>> p;
  addRoof(&p, 0.25f, 0.25f, 9.75f, 9.75f, 8);
  const std::size_t first = p.size();
  addRoof(&p, 10.5f, 0.25f, 20.25f, 9.75f, 8);  // as high: one Euclidean cluster
  const eval::ObjectScores clustered = eval::scoreObjects(p, truth, {});
  EXPECT_EQ(clustered.predicted, 1u);
  EXPECT_EQ(clustered.matched, 0u);
  std::vector<std::vector<std::size_t>> groups(3);
  for (std::size_t i = 0; i < p.size(); ++i) groups[i < first ? 0 : 1].push_back(i);
  groups[2] = {0, 1, 2};  // under min_points (20): not an object
  const eval::ObjectScores grouped = eval::scoreGroupedPoints(p, groups, truth, {});
  EXPECT_EQ(grouped.predicted, 2u);
  EXPECT_EQ(grouped.matched, 2u);
  EXPECT_NEAR(grouped.f1, 1.0, 1e-12);
  ASSERT_EQ(grouped.matches.size(), 2u);
  for (const auto& [t, g] : grouped.matches) EXPECT_EQ(t, g);
  EXPECT_NEAR(grouped.best_iou[0], 0.9025, 0.01);  // the hull of the centres: 9.5 x 9.5
  EXPECT_NEAR(grouped.best_iou[1], 0.9025, 0.01);  // 10.5 .. 20.0 x 0.25 .. 9.75
  // An index outside the points is an error, not a read past the end.
  EXPECT_THROW(eval::scoreGroupedPoints(p, {std::vector<std::size_t>(20, p.size())}, truth, {}),
               std::out_of_range);
}

TEST(ObjectScores, AutoToleranceIsFourSpacingsBetweenOneAndThreeMetres) {
  EXPECT_DOUBLE_EQ(eval::autoClusterTolerance(0.1), 1.0);   // floor
  EXPECT_DOUBLE_EQ(eval::autoClusterTolerance(0.5), 2.0);   // 4 x spacing
  EXPECT_DOUBLE_EQ(eval::autoClusterTolerance(1.68), 3.0);  // a mission's spacing: the ceiling
  EXPECT_DOUBLE_EQ(eval::autoClusterTolerance(0.0), 1.0);
}

}  // namespace
}  // namespace sadsplat
