// Open3D in C++: lossless Gaussian round trip, Open3D's own PLY reader on sadsplat's model.ply,
// the semantic cloud as a legacy cloud, and Open3D algorithms on one class.
#include <gtest/gtest.h>

#include <open3d/t/io/PointCloudIO.h>

#include <cmath>
#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/interop/open3d_conversion.h"
#include "sadsplat/io/gaussian_ply.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

TEST(Open3dConversion, GaussianRoundTripIsBitExact) {
  auto cloud = test::randomGaussians(123, 31);
  cloud[0].label = kUnlabelled;
  const auto o3d = interop::toOpen3d(cloud);
  EXPECT_EQ(o3d.GetPointPositions().GetShape(), open3d::core::SizeVector({123, 3}));
  EXPECT_TRUE(o3d.HasPointAttr("f_rest_44"));
  EXPECT_TRUE(o3d.HasPointAttr("feature_31"));
  EXPECT_EQ(o3d.GetPointAttr("label").GetDtype(), open3d::core::Int32);
  EXPECT_EQ(o3d.GetPointAttr("label")[0][0].Item<int32_t>(), -1);
  EXPECT_EQ(o3d.GetPointAttr("opacity")[7][0].Item<float>(), cloud[7].opacity);
  const auto back = interop::fromOpen3d(o3d);
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_TRUE(bitwiseEqual(back[i], cloud[i])) << i;
}

// Open3D's C++ reader of sadsplat's model.ply gives the same Gaussians as sadsplat's reader.
TEST(Open3dConversion, Open3dReadsOurPlyToTheSameGaussians) {
  test::TempDir dir;
  auto cloud = test::randomGaussians(40, 32);
  cloud[3].label = kUnlabelled;
  io::writeGaussianPly(dir.file("m.ply"), cloud);
  open3d::t::geometry::PointCloud o3d;
  ASSERT_TRUE(open3d::t::io::ReadPointCloud(dir.file("m.ply"), o3d));
  const auto back = interop::fromOpen3d(o3d);
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_TRUE(bitwiseEqual(back[i], cloud[i])) << i;
}

TEST(Open3dConversion, MissingOrMisshapenAttributesAreErrors) {
  auto o3d = interop::toOpen3d(test::randomGaussians(5, 33));
  o3d.RemovePointAttr("rot_2");
  try {
    interop::fromOpen3d(o3d);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "attribute rot_2");
  }
  auto bad = interop::toOpen3d(test::randomGaussians(5, 33));
  bad.SetPointAttr("opacity", open3d::core::Tensor::Zeros({5, 2}, open3d::core::Float32));
  EXPECT_THROW(interop::fromOpen3d(bad), Error);
}

// Ground (class 0) on the plane z = 1, cars (class 1) in two separate blobs: Open3D's plane
// segmentation on the ground class and DBSCAN on the car class find them.
TEST(Open3dConversion, Open3dAlgorithmsOnAClass) {
  pcl::PointCloud<GaussianPoint> cloud;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      GaussianPoint p;
      p.x = i * 0.5f;
      p.y = j * 0.5f;
      p.z = 1.0f;
      p.label = 0;
      cloud.push_back(p);
    }
  }
  for (int blob = 0; blob < 2; ++blob) {
    for (int k = 0; k < 40; ++k) {
      GaussianPoint p;
      p.x = 3.0f + 8.0f * blob + 0.05f * (k % 7);
      p.y = 5.0f + 0.05f * (k / 7);
      p.z = 1.5f + 0.02f * (k % 3);
      p.label = 1;
      cloud.push_back(p);
    }
  }
  const std::vector<ClassInfo> classes = {{"road", {128, 64, 128}, "road"},
                                          {"car", {0, 0, 142}, "car"}};
  std::vector<int> labels;
  const auto legacy = interop::toOpen3dLegacy(toSemanticCloud(cloud, classes), &labels);
  ASSERT_EQ(legacy->points_.size(), cloud.size());
  EXPECT_NEAR(legacy->colors_[0].x(), 128 / 255.0, 1e-12);
  std::vector<std::size_t> ground, cars;
  for (std::size_t i = 0; i < labels.size(); ++i) (labels[i] == 0 ? ground : cars).push_back(i);
  const auto road = legacy->SelectByIndex(ground);
  const auto [plane, inliers] = road->SegmentPlane(0.01, 3, 200);
  EXPECT_EQ(inliers.size(), ground.size());
  EXPECT_NEAR(std::fabs(plane.z()), 1.0, 1e-6);  // the plane's normal is z
  EXPECT_NEAR(std::fabs(plane.w()), 1.0, 1e-6);  // at z = 1
  const auto car_points = legacy->SelectByIndex(cars);
  const std::vector<int> clusters = car_points->ClusterDBSCAN(0.5, 5);
  EXPECT_EQ(std::set<int>(clusters.begin(), clusters.end()), (std::set<int>{0, 1}));
}

}  // namespace
}  // namespace sadsplat
