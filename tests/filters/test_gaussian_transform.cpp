// transformGaussians moves Gaussians rigidly: centres, covariances and view-dependent colour.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/gaussian_transform.h"
#include "sadsplat/gaussians/raster_math.h"  // the rasterizer's SH basis: an independent reference
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

// The RGB colour of SH degrees 0..3 of `p` seen from direction d (as the rasterizer sums it).
Eigen::Vector3d shColourOf(const GaussianPoint& p, const Eigen::Vector3d& d) {
  const double dir[3] = {d.x(), d.y(), d.z()};
  double b[16];
  gaussians::raster::shBasis(dir, 3, b);
  Eigen::Vector3d c;
  for (int ch = 0; ch < 3; ++ch) {
    c[ch] = b[0] * p.f_dc[ch];
    for (int k = 0; k < 15; ++k) c[ch] += b[k + 1] * p.f_rest[ch * kShRestPerChannel + k];
  }
  return c;
}

Eigen::Matrix3d turnedCovarianceOf(const GaussianPoint& p) {
  const Eigen::Matrix3d r =
      Eigen::Quaterniond(p.rot[0], p.rot[1], p.rot[2], p.rot[3]).normalized().toRotationMatrix();
  const Eigen::Vector3d s(std::exp(2.0 * p.scale[0]), std::exp(2.0 * p.scale[1]),
                          std::exp(2.0 * p.scale[2]));
  return r * s.asDiagonal() * r.transpose();
}

Eigen::Matrix3d someRotation(int seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

TEST(GaussianTransform, ViewDependentColourTurnsWithTheScene) {
  const auto cloud = test::randomGaussians(20, 3);
  for (int seed : {1, 2, 3}) {
    const Eigen::Matrix3d r = someRotation(seed);
    pcl::PointCloud<GaussianPoint> moved;
    filters::transformGaussians(cloud, moved, r);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      for (int s = 0; s < 8; ++s) {
        const Eigen::Vector3d d = someRotation(100 + s).col(0);
        const Eigen::Vector3d before = shColourOf(cloud[i], d);
        const Eigen::Vector3d after = shColourOf(moved[i], r * d);
        EXPECT_LT((before - after).norm(), 1e-4 * (1 + before.norm())) << "Gaussian " << i;
      }
    }
  }
}

TEST(GaussianTransform, CentresMoveAndCovariancesTurn) {
  const auto cloud = test::randomGaussians(30, 4);
  const Eigen::Matrix3d r = someRotation(7);
  const Eigen::Vector3d t(10, -3, 0.5);
  pcl::PointCloud<GaussianPoint> moved;
  filters::transformGaussians(cloud, moved, r, t);
  ASSERT_EQ(moved.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d want = r * Eigen::Vector3d(cloud[i].x, cloud[i].y, cloud[i].z) + t;
    EXPECT_NEAR(moved[i].x, want.x(), 1e-5);
    EXPECT_NEAR(moved[i].y, want.y(), 1e-5);
    EXPECT_NEAR(moved[i].z, want.z(), 1e-5);
    const Eigen::Matrix3d expected = r * turnedCovarianceOf(cloud[i]) * r.transpose();
    EXPECT_LT((turnedCovarianceOf(moved[i]) - expected).norm(), 1e-4 * (1 + expected.norm()));
    EXPECT_EQ(moved[i].label, cloud[i].label);
    EXPECT_EQ(moved[i].f_dc[0], cloud[i].f_dc[0]);
    EXPECT_EQ(moved[i].opacity, cloud[i].opacity);
  }
}

TEST(GaussianTransform, TheIdentityKeepsEveryValue) {
  const auto cloud = test::randomGaussians(10, 5);
  pcl::PointCloud<GaussianPoint> same;
  filters::transformGaussians(cloud, same, Eigen::Matrix3d::Identity());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int k = 0; k < 3 * kShRestPerChannel; ++k) {
      EXPECT_NEAR(same[i].f_rest[k], cloud[i].f_rest[k], 1e-5);
    }
  }
}

TEST(GaussianTransform, AMirrorIsRefused) {
  const auto cloud = test::randomGaussians(3, 6);
  pcl::PointCloud<GaussianPoint> out;
  Eigen::Matrix3d mirror = Eigen::Matrix3d::Identity();
  mirror(2, 2) = -1;
  EXPECT_THROW(filters::transformGaussians(cloud, out, mirror), Error);
  EXPECT_THROW(filters::transformGaussians(cloud, out, 2 * Eigen::Matrix3d::Identity()), Error);
}

}  // namespace
}  // namespace sadsplat
