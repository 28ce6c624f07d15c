#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"

namespace sadsplat {
namespace {

std::vector<ClassInfo> twoClasses() {
  return {{"road", {128, 64, 128}, "a road"}, {"tree", {0, 200, 0}, "a tree"}};
}

TEST(SemanticCloud, ColoursPointsByClassAndKeepsLabels) {
  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(3);
  cloud[0].x = 1.f;
  cloud[0].label = 1;
  cloud[1].label = 0;
  cloud[2].label = kUnlabelled;
  const auto semantic = toSemanticCloud(cloud, twoClasses());
  ASSERT_EQ(semantic.size(), 3u);
  EXPECT_EQ(semantic[0].x, 1.f);
  EXPECT_EQ(semantic[0].label, 1u);
  EXPECT_EQ(semantic[0].g, 200);
  EXPECT_EQ(semantic[1].r, 128);
  EXPECT_EQ(semantic[2].label, kUnlabelled);
  EXPECT_EQ(semantic[2].r, kUnlabelledGrey);
}

TEST(SemanticCloud, RejectsALabelOutsideTheClassList) {
  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(1);
  cloud[0].label = 7;
  try {
    toSemanticCloud(cloud, twoClasses());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "label of point 0");
    EXPECT_EQ(e.got(), "7");
  }
}

TEST(ClassInfo, FindsClassesByName) {
  EXPECT_EQ(findClass(twoClasses(), "tree"), 1u);
  EXPECT_FALSE(findClass(twoClasses(), "water").has_value());
}

}  // namespace
}  // namespace sadsplat
