// The raised-class check on the cloud (pipeline/raised_gaussians.h, geo::groundUnderPoints): a
// sloped street between two buildings, with building Gaussians lying on the street that join
// them, and known answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/ground_model.h"
#include "sadsplat/pipeline/raised_gaussians.h"

namespace sadsplat {
namespace {

constexpr std::uint32_t kRoad = 0, kBuilding = 1;

// The ground model's own test slope (geo/test_ground_model.cpp); at 5 % the edge windows'
// extrapolation errs by up to 1.6 m.
float slope(float x, float y) { return 50.f + 0.02f * x - 0.01f * y; }

GaussianPoint gaussian(float x, float y, float z, std::uint32_t label, float opacity_logit = 4) {
  GaussianPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.label = label;
  p.opacity = opacity_logit;
  return p;
}

// 100 x 100 m of road every metre on a slope; two buildings 12 m high (roof Gaussians every
// metre, walls every metre up their sides) at x in [20, 40) and [60, 80), y in [30, 70); twenty
// building Gaussians on the street between them (x 41..59, y 50), 0.2 m above it; translucent
// floaters (opacity 0.02) 30 m below the ground, left out of the ground (not opaque).
pcl::PointCloud<GaussianPoint> street(std::vector<std::size_t>* bridge) {
  pcl::PointCloud<GaussianPoint> c;
  const auto inBuilding = [](float x, float y) {
    return ((x >= 20 && x < 40) || (x >= 60 && x < 80)) && y >= 30 && y < 70;
  };
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      const float x = i + 0.5f, y = j + 0.5f;
      if (inBuilding(x, y)) {
        c.push_back(gaussian(x, y, slope(x, y) + 12, kBuilding));
        const bool wall =
            x < 21 || (x >= 39 && x < 41) || (x >= 59 && x < 61) || x >= 79 || y < 31 || y >= 69;
        for (int h = 1; wall && h < 12; h += 1)
          c.push_back(gaussian(x, y, slope(x, y) + h, kBuilding));
      } else {
        c.push_back(gaussian(x, y, slope(x, y), kRoad));
      }
      if ((i * 7 + j) % 23 == 0) c.push_back(gaussian(x, y, slope(x, y) - 30, kRoad, -4));
    }
  }
  for (int i = 41; i < 60; ++i) {
    bridge->push_back(c.size());
    c.push_back(gaussian(i + 0.5f, 50.5f, slope(i + 0.5f, 50.5f) + 0.2f, kBuilding));
  }
  return c;
}

// A scene whose up is +z: one camera looking straight down.
io::Scene lookingDown() {
  io::Scene s;
  io::View v;
  v.name = "nadir";
  v.camera.width = v.camera.height = 100;
  v.camera.fx = v.camera.fy = 50;
  v.camera.cx = v.camera.cy = 50;
  v.camera.qvec = {0, 1, 0, 0};  // R = diag(1, -1, -1)
  v.camera.tvec = {-50, 50, 200};
  v.train = true;
  s.views.push_back(v);
  s.classes = {{"road", {128, 128, 128}}, {"building", {200, 0, 0}}};
  return s;
}

TEST(RaisedGaussians, TheGroundUnderPointsFollowsTheStreetNotTheRoofsOrTheFloaters) {
  std::vector<std::size_t> bridge;
  const auto c = street(&bridge);
  std::vector<float> e, n, up;
  std::vector<std::uint8_t> use;
  for (const GaussianPoint& p : c) {
    e.push_back(p.x), n.push_back(p.y), up.push_back(p.z);
    use.push_back(p.opacity > 0);
  }
  const std::vector<float> ground = geo::groundUnderPoints(e, n, up, use, 1.0, 20.0);
  ASSERT_EQ(ground.size(), c.size());
  double worst = 0;
  for (std::size_t i = 0; i < c.size(); ++i)
    worst = std::max<double>(worst, std::abs(ground[i] - slope(c[i].x, c[i].y)));
  EXPECT_LT(worst, 1.25);  // half the raised height: every roof stands, every street lies
  EXPECT_THROW(geo::groundUnderPoints(e, n, up, use, 0.0, 20.0), Error);
  up.pop_back();
  EXPECT_THROW(geo::groundUnderPoints(e, n, up, use, 1.0, 20.0), Error);
  // No point marked: no ground.
  std::fill(use.begin(), use.end(), 0);
  up.push_back(0);
  EXPECT_TRUE(std::isnan(geo::groundUnderPoints(e, n, up, use, 1.0, 20.0)[0]));
}

TEST(RaisedGaussians, ListsExactlyTheBuildingGaussiansOnTheStreet) {
  std::vector<std::size_t> bridge;
  const auto c = street(&bridge);
  const geo::LowRaisedCells low = pipeline::findLowRaisedGaussians(c, lookingDown(), 2);
  ASSERT_EQ(low.raised, std::vector<int>{static_cast<int>(kBuilding)});
  ASSERT_EQ(low.ground, std::vector<int>{static_cast<int>(kRoad)});
  std::vector<std::size_t> listed = low.cells;
  std::sort(listed.begin(), listed.end());
  // The bridge, and the walls' lowest Gaussians (1..3 m up: below 0.33 x 12 m), nothing else.
  std::size_t walls_low = 0;
  for (std::size_t i : listed) {
    if (std::find(bridge.begin(), bridge.end(), i) != bridge.end()) continue;
    EXPECT_EQ(c[i].label, kBuilding) << i;
    EXPECT_LT(c[i].z - slope(c[i].x, c[i].y), 0.33 * 12 + 0.5) << i;
    ++walls_low;
  }
  for (std::size_t i : bridge)
    EXPECT_TRUE(std::binary_search(listed.begin(), listed.end(), i)) << i;
  EXPECT_EQ(listed.size(), bridge.size() + walls_low);
  pipeline::RaisedGaussianOptions off;
  off.share = 0;
  EXPECT_TRUE(pipeline::findLowRaisedGaussians(c, lookingDown(), 2, off).cells.empty());
  off.share = 1.5;
  EXPECT_THROW(pipeline::findLowRaisedGaussians(c, lookingDown(), 2, off), Error);
}

}  // namespace
}  // namespace sadsplat
