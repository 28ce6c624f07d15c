// PCD through PCL: exact Gaussian round trip and the plain semantic cloud.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/io/pcd.h"
#include "test_support/test_support.h"

#if SADSPLAT_HAVE_PCL_IO
#include <pcl/io/pcd_io.h>
#endif

namespace sadsplat {
namespace {

TEST(Pcd, GaussianRoundTripIsBitExact) {
  if (!io::havePcdSupport()) GTEST_SKIP() << "built without pcl_io";
  test::TempDir dir;
  const auto cloud = test::randomGaussians(50, 21);
  io::savePcd(dir.file("g.pcd"), cloud);
  const auto back = io::loadGaussianPcd(dir.file("g.pcd"));
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_TRUE(bitwiseEqual(back[i], cloud[i])) << i;
}

TEST(Pcd, SemanticCloudIsAPlainXyzRgblCloud) {
#if SADSPLAT_HAVE_PCL_IO
  test::TempDir dir;
  auto cloud = test::randomGaussians(30, 22, 2);
  const std::vector<ClassInfo> classes = {{"a", {10, 20, 30}, "a"}, {"b", {40, 50, 60}, "b"}};
  io::savePcd(dir.file("s.pcd"), toSemanticCloud(cloud, classes));
  pcl::PointCloud<pcl::PointXYZRGBL> back;
  ASSERT_EQ(pcl::io::loadPCDFile(dir.file("s.pcd"), back), 0);
  ASSERT_EQ(back.size(), 30u);
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].x, cloud[i].x);
    EXPECT_EQ(back[i].label, cloud[i].label);
    if (cloud[i].label != kUnlabelled) {
      EXPECT_EQ(back[i].b, classes[cloud[i].label].color[2]);
    }
  }
#else
  GTEST_SKIP() << "built without pcl_io";
#endif
}

TEST(Pcd, MissingFileOrFieldIsAnError) {
  if (!io::havePcdSupport()) GTEST_SKIP() << "built without pcl_io";
  test::TempDir dir;
  EXPECT_THROW(io::loadGaussianPcd(dir.file("none.pcd")), Error);
  test::writeFile(dir.file("xyz.pcd"),
                  "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\n"
                  "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n");
  try {
    io::loadGaussianPcd(dir.file("xyz.pcd"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "field f_dc");
  }
}

}  // namespace
}  // namespace sadsplat
