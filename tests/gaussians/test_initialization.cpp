#include <gtest/gtest.h>

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/initialization.h"

namespace sadsplat {
namespace {

TEST(Initialization, ScalesAreTheMeanDistanceToThreeNeighbours) {
  // Points on a line at 0, 1, 3, 6, 10: neighbours of 0 are 1, 3, 6 -> mean 10/3.
  std::vector<io::ScenePoint> points;
  for (float x : {0.f, 1.f, 3.f, 6.f, 10.f}) points.push_back({{x, 0.f, 0.f}, {255, 0, 128}});
  const auto cloud = gaussians::initialCloud(points);
  ASSERT_EQ(cloud.size(), 5u);
  EXPECT_NEAR(std::exp(cloud[0].scale[0]), 10.0 / 3.0, 1e-5);
  EXPECT_NEAR(std::exp(cloud[2].scale[2]), (2.0 + 3.0 + 3.0) / 3.0, 1e-5);  // 1, 6, 0
  EXPECT_NEAR(1.0 / (1.0 + std::exp(-cloud[0].opacity)), 0.1, 1e-6);
  EXPECT_NEAR(gaussians::shDcToRgb(cloud[0].f_dc[0]), 1.0, 1e-6);
  EXPECT_NEAR(gaussians::shDcToRgb(cloud[0].f_dc[1]), 0.0, 1e-6);
  EXPECT_EQ(cloud[0].rot[0], 1.f);
  EXPECT_EQ(cloud[0].label, kUnlabelled);
  EXPECT_LT(std::abs(cloud[0].feature[0]), 0.1f);
}

TEST(Initialization, IsSeeded) {
  std::vector<io::ScenePoint> points(10);
  for (int i = 0; i < 10; ++i) points[i].xyz = {float(i), float(i * i), 0.f};
  const auto a = gaussians::initialCloud(points), b = gaussians::initialCloud(points);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(bitwiseEqual(a[i], b[i]));
  gaussians::InitOptions other;
  other.seed = 43;
  EXPECT_NE(gaussians::initialCloud(points, other)[0].feature[0], a[0].feature[0]);
}

TEST(Initialization, TooFewPointsIsAnError) {
  EXPECT_THROW(gaussians::initialCloud(std::vector<io::ScenePoint>(3)), Error);
}

}  // namespace
}  // namespace sadsplat
