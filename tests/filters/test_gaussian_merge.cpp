// Moment-matched merges: mixture moments, classes apart, the count compactGaussians reaches.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/gaussian_merge.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

Eigen::Matrix3d mixtureCovarianceOf(const GaussianPoint& p) {
  const Eigen::Matrix3d r =
      Eigen::Quaterniond(p.rot[0], p.rot[1], p.rot[2], p.rot[3]).normalized().toRotationMatrix();
  const Eigen::Vector3d s(std::exp(2.0 * p.scale[0]), std::exp(2.0 * p.scale[1]),
                          std::exp(2.0 * p.scale[2]));
  return r * s.asDiagonal() * r.transpose();
}

// Opacity x the footprint area s0 s1 + s0 s2 + s1 s2 (gaussian_merge.h).
double massOf(const GaussianPoint& p) {
  const double s0 = std::exp(double(p.scale[0])), s1 = std::exp(double(p.scale[1])),
               s2 = std::exp(double(p.scale[2]));
  return 1.0 / (1.0 + std::exp(-double(p.opacity))) * (s0 * s1 + s0 * s2 + s1 * s2);
}

TEST(GaussianMerge, AGroupOfOneIsKeptBitForBit) {
  const auto cloud = test::randomGaussians(4, 11);
  EXPECT_TRUE(bitwiseEqual(filters::mergeGaussians(cloud, {2}), cloud[2]));
}

TEST(GaussianMerge, TheMergeHasTheMixturesMassWeightedMoments) {
  auto cloud = test::randomGaussians(5, 12);
  for (auto& p : cloud) {
    for (float& s : p.scale) s = -1.0f + 0.2f * s;
    p.label = 1;
  }
  const GaussianPoint m = filters::mergeGaussians(cloud, {0, 1, 2, 3, 4});
  double total = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double dc = 0;
  for (const auto& p : cloud) {
    total += massOf(p);
    mean += massOf(p) * Eigen::Vector3d(p.x, p.y, p.z);
    dc += massOf(p) * p.f_dc[0];
  }
  mean /= total;
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& p : cloud) {
    const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.z) - mean;
    second += massOf(p) / total * (mixtureCovarianceOf(p) + d * d.transpose());
  }
  EXPECT_NEAR(m.x, mean.x(), 1e-5);
  EXPECT_NEAR(m.y, mean.y(), 1e-5);
  EXPECT_NEAR(m.z, mean.z(), 1e-5);
  EXPECT_LT((mixtureCovarianceOf(m) - second).norm(), 1e-4 * second.norm());
  EXPECT_NEAR(m.f_dc[0], dc / total, 1e-5);
  EXPECT_EQ(m.label, 1u);
  // Mass kept (opacity x area) unless the opacity had to be capped at 0.999.
  const double alpha = 1.0 / (1.0 + std::exp(-double(m.opacity)));
  if (alpha < 0.99) EXPECT_NEAR(massOf(m), total, 1e-4 * total);
}

TEST(GaussianMerge, VoxelsKeepClassesApartUnlessAskedNot) {
  pcl::PointCloud<GaussianPoint> cloud = test::randomGaussians(4, 13);
  for (std::size_t i = 0; i < 4; ++i) {
    cloud[i].x = 0.1f * i;
    cloud[i].y = cloud[i].z = 0;
    cloud[i].label = i % 2;
  }
  std::vector<std::size_t> group;
  const auto apart = filters::mergeInVoxels(cloud, {1.0, true}, &group);
  ASSERT_EQ(apart.size(), 2u);
  EXPECT_EQ(group, (std::vector<std::size_t>{0, 1, 0, 1}));
  EXPECT_EQ(apart[0].label, 0u);
  EXPECT_EQ(apart[1].label, 1u);
  EXPECT_EQ(filters::mergeInVoxels(cloud, {1.0, false}).size(), 1u);
  EXPECT_EQ(filters::countVoxelGroups(cloud, {0.05, true}), 4u);
  EXPECT_THROW(filters::mergeInVoxels(cloud, {0.0, true}), Error);
}

TEST(GaussianMerge, CompactReachesTheTargetKeepingEveryClass) {
  const auto cloud = test::randomGaussians(3000, 14, 3);
  for (std::size_t target : {1000u, 200u, 40u}) {
    const filters::CompactResult r = filters::compactGaussians(cloud, target);
    EXPECT_EQ(r.cloud.size(), target);  // the k-d split makes exactly the target's groups
    EXPECT_GT(r.group_extent, 0);
    std::set<std::uint32_t> labels_in, labels_out;
    for (const auto& p : cloud) labels_in.insert(p.label);
    for (const auto& p : r.cloud) labels_out.insert(p.label);
    EXPECT_EQ(labels_in, labels_out);  // class-aware: no class vanishes
  }
  EXPECT_EQ(filters::compactGaussians(cloud, 5000).cloud.size(), cloud.size());
  EXPECT_THROW(filters::compactGaussians(cloud, 2), Error);  // 4 labels (3 + unlabelled)
  EXPECT_EQ(filters::compactGaussians(cloud, 2, false).cloud.size(), 2u);  // classes merge
  EXPECT_THROW(filters::compactGaussians(cloud, 0), Error);
}

}  // namespace
}  // namespace sadsplat
