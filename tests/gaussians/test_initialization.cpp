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

// Two cameras 10 apart looking down +z at a plane: every random point lies in front of both and
// inside both images, the draw is seeded, and cameras that share no view are an error.
TEST(Initialization, RandomPointsLieInTheCamerasCommonView) {
  std::vector<io::PinholeCamera> cameras(2);
  for (int i = 0; i < 2; ++i) {
    cameras[i].width = 64;
    cameras[i].height = 48;
    cameras[i].fx = cameras[i].fy = 40;
    cameras[i].cx = 32;
    cameras[i].cy = 24;
    cameras[i].tvec = {i == 0 ? 5.0 : -5.0, 0.0, 0.0};  // centres at x = -5 and x = +5
  }
  const auto points = gaussians::randomPointsInView(cameras, 500, 7);
  ASSERT_EQ(points.size(), 500u);
  for (const auto& p : points) {
    for (const auto& c : cameras) {
      const double z = p.xyz[2];
      ASSERT_GT(z, 0.0);
      const double u = c.fx * (p.xyz[0] + c.tvec[0]) / z + c.cx, v = c.fy * p.xyz[1] / z + c.cy;
      EXPECT_TRUE(u >= 0 && u < 64 && v >= 0 && v < 48) << u << " " << v;
    }
    // Depth along the drawing camera's ray: at most 2 x 1.5 x 5.
    EXPECT_LE(p.xyz[2], 15.f);
  }
  const auto again = gaussians::randomPointsInView(cameras, 500, 7);
  EXPECT_EQ(again[123].xyz, points[123].xyz);
  EXPECT_NE(gaussians::randomPointsInView(cameras, 500, 8)[0].xyz, points[0].xyz);
  // Back to back: no point is seen by both.
  cameras[1].qvec = {0, 0, 1, 0};  // 180 degrees about y
  EXPECT_THROW(gaussians::randomPointsInView(cameras, 100, 7), Error);
  EXPECT_THROW(gaussians::randomPointsInView({}, 100, 7), Error);
}

TEST(Initialization, TheInitChoice) {
  using gaussians::InitMode;
  EXPECT_FALSE(gaussians::initialisesRandomly(InitMode::kAuto, 4));
  EXPECT_TRUE(gaussians::initialisesRandomly(InitMode::kAuto, 3));
  EXPECT_TRUE(gaussians::initialisesRandomly(InitMode::kRandom, 1000));
  EXPECT_FALSE(gaussians::initialisesRandomly(InitMode::kPoints, 4));
  EXPECT_THROW(gaussians::initialisesRandomly(InitMode::kPoints, 0), Error);
  EXPECT_THROW(gaussians::parseChoice<InitMode>("sfm", "test", "init"), Error);
}

TEST(Initialization, TooFewPointsIsAnError) {
  EXPECT_THROW(gaussians::initialCloud(std::vector<io::ScenePoint>(3)), Error);
}

}  // namespace
}  // namespace sadsplat
