// The 3D scores of a per-class cloud on a hand-made truth with answers worked out by hand: a
// ground plane (class 0 for x < 0, class 1 for x >= 0) and a 2 x 2 x 3 m box of class 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sadsplat/eval/cloud_scores.h"

namespace sadsplat {
namespace {

eval::TruthSurface handMadeTruth(const std::array<float, 3>& p) {
  eval::TruthSurface ground{std::fabs(p[2]), static_cast<std::uint8_t>(p[0] < 0 ? 0 : 1)};
  // Distance to the box [0, 2] x [0, 2] x [0, 3] (outside: Euclidean; inside: nearest face).
  const float lo[3] = {0, 0, 0}, hi[3] = {2, 2, 3};
  float outside2 = 0, inside = 1e30f;
  bool in = true;
  for (int k = 0; k < 3; ++k) {
    const float d = std::max(lo[k] - p[k], p[k] - hi[k]);
    if (d > 0) {
      outside2 += d * d;
      in = false;
    } else {
      inside = std::min(inside, -d);
    }
  }
  const float box = in ? inside : std::sqrt(outside2);
  return box < ground.distance ? eval::TruthSurface{box, 2} : ground;
}

TEST(CloudScores, ClassesDistancesAndCompletenessOfAHandMadeWorld) {
  std::vector<eval::CloudPoint> points = {
      {{-5, 0, 0.1f}, 0, 1.0f},  // right class, 0.1 m off the ground
      {{5, 0, 0.2f}, 0, 0.2f},   // wrong class (truth 1), not opaque
      {{1, 1, 3.3f}, 2, 0.9f},   // right class, 0.3 m above the roof
      {{5, 5, 2.0f}, 1, 0.8f},   // right class, a floater 2 m above the ground
      {{-3, 0, 0.0f}, -1, 1.0f}, // no class: not scored for classes, counts for geometry
  };
  const std::vector<eval::SurfaceSample> surface = {
      {{-5, 0, 0}, 0}, {{5, 0, 0}, 1}, {{1, 1, 3}, 2}, {{-3, 0.4f, 0}, 0}, {{9, 9, 0}, 255}};
  eval::CloudScoreOptions o;
  o.num_classes = 3;
  const eval::CloudScores s = eval::scoreCloud(points, handMadeTruth, surface, o);
  // Plain: (truth, predicted) = (0, 0), (1, 0), (2, 2), (1, 1).
  EXPECT_EQ(s.points, 4u);
  EXPECT_NEAR(s.iou[0], 0.5, 1e-9);
  EXPECT_NEAR(s.iou[1], 0.5, 1e-9);
  EXPECT_NEAR(s.iou[2], 1.0, 1e-9);
  EXPECT_NEAR(s.miou, 2.0 / 3.0, 1e-9);
  EXPECT_NEAR(s.oacc, 0.75, 1e-9);
  // Opacity-weighted: the wrong Gaussian weighs 0.2.
  EXPECT_NEAR(s.weighted_iou[0], 1.0 / 1.2, 1e-6);
  EXPECT_NEAR(s.weighted_iou[1], 0.8, 1e-6);
  EXPECT_NEAR(s.weighted_oacc, 2.7 / 2.9, 1e-6);
  // Opaque (>= 0.5): distances 0.1, 0.3, 2.0, 0.0 -> nearest-rank median 0.3, 90th 2.0.
  EXPECT_EQ(s.opaque, 4u);
  EXPECT_NEAR(s.median_metres, 0.3, 1e-6);
  EXPECT_NEAR(s.p90_metres, 2.0, 1e-6);
  EXPECT_NEAR(s.share_near, 0.75, 1e-9);
  EXPECT_NEAR(s.share_far, 0.25, 1e-9);
  // Per class of the nearest surface (opaque only): class 0 has A (0.1) and E (0.0), class 1
  // has D (2.0), class 2 has C (0.3).
  EXPECT_EQ(s.opaque_per_class, (std::vector<std::size_t>{2, 1, 1}));
  EXPECT_NEAR(s.median_per_class[1], 2.0, 1e-6);
  EXPECT_NEAR(s.share_far_per_class[0], 0.0, 1e-9);
  EXPECT_NEAR(s.share_far_per_class[1], 1.0, 1e-9);
  EXPECT_EQ(s.confusion, (std::vector<std::size_t>{1, 0, 0, 1, 1, 0, 0, 0, 1}));
  // Over all five: 0.1, 0.2, 0.3, 2.0, 0.0 -> median 0.2, 90th 2.0.
  EXPECT_NEAR(s.median_all_metres, 0.2, 1e-6);
  EXPECT_NEAR(s.p90_all_metres, 2.0, 1e-6);
  // Completeness within 0.5 m: class 0's two samples covered (0.1 m and 0.4 m away), class 1's
  // sample only by a transparent Gaussian (not covered), the roof's by the 0.3 m one; the
  // unlabelled sample is not counted.
  EXPECT_EQ(s.samples[0], 2u);
  EXPECT_NEAR(s.completeness[0], 1.0, 1e-9);
  EXPECT_NEAR(s.completeness[1], 0.0, 1e-9);
  EXPECT_NEAR(s.completeness[2], 1.0, 1e-9);
  EXPECT_NEAR(s.completeness_all, 0.75, 1e-9);
}

TEST(CloudScores, AClassAbsentFromTruthAndModelIsNotAveraged) {
  const std::vector<eval::CloudPoint> points = {{{-1, 0, 0}, 0, 1.f}};
  eval::CloudScoreOptions o;
  o.num_classes = 3;
  const eval::CloudScores s = eval::scoreCloud(points, handMadeTruth, {}, o);
  EXPECT_EQ(s.iou[1], -1.0);
  EXPECT_EQ(s.iou[2], -1.0);
  EXPECT_NEAR(s.miou, 1.0, 1e-9);
  EXPECT_EQ(s.completeness[0], -1.0);  // no samples
  o.num_classes = 0;
  EXPECT_ANY_THROW(eval::scoreCloud(points, handMadeTruth, {}, o));
}

// Over a map's area: the points whose centre lies over the rectangle (edges included), heights
// ignored; scored, a far-off floater beyond the area no longer counts.
TEST(CloudScores, PointsOverTheMapsAreaLeaveOutWhatLiesBeyond) {
  const std::vector<eval::CloudPoint> points = {{{-1, 0, 0}, 0, 1.f},
                                                {{1, 1, 3.1f}, 2, 1.f},
                                                {{2, -2, 0}, 1, 1.f},    // on the corner
                                                {{2.01f, 0, 0}, 1, 1.f},  // just beyond x1
                                                {{0, 0, 50}, 1, 1.f},   // high above: over it
                                                {{-40, 30, 12}, 0, 1.f}};  // far away, floating
  const std::vector<eval::CloudPoint> over = eval::pointsOver(points, -2, -2, 2, 2);
  ASSERT_EQ(over.size(), 4u);
  EXPECT_EQ(over[0].xyz[0], -1.f);
  EXPECT_EQ(over[1].xyz[2], 3.1f);
  EXPECT_EQ(over[2].xyz[0], 2.f);
  EXPECT_EQ(over[3].xyz[2], 50.f);
  eval::CloudScoreOptions o;
  o.num_classes = 3;
  const eval::CloudScores all = eval::scoreCloud(points, handMadeTruth, {}, o);
  const eval::CloudScores inside = eval::scoreCloud(over, handMadeTruth, {}, o);
  // Within 0.5 m: 4 of 6 everywhere (the floaters at 50 m and 12 m not), 3 of 4 over the area.
  EXPECT_NEAR(all.share_near, 4.0 / 6, 1e-9);
  EXPECT_NEAR(inside.share_near, 3.0 / 4, 1e-9);
  EXPECT_EQ(inside.opaque, 4u);
  EXPECT_TRUE(eval::pointsOver(points, 5, 5, 6, 6).empty());
  EXPECT_ANY_THROW(eval::pointsOver(points, 1, 0, 0, 1));
  EXPECT_ANY_THROW(eval::pointsOver(points, 0, 1, 1, 0));
}

}  // namespace
}  // namespace sadsplat
