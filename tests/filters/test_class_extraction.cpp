// ClassExtraction behaves like a PCL FilterIndices filter.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/class_extraction.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

TEST(ClassExtraction, KeepsOneClassAndNegativeGivesTheComplement) {
  auto cloud = std::make_shared<pcl::PointCloud<GaussianPoint>>(test::randomGaussians(200, 41, 3));
  filters::ClassExtraction<GaussianPoint> filter(true);
  filter.setInputCloud(cloud);
  filter.setClassId(2);
  pcl::Indices kept, rest;
  filter.filter(kept);
  const pcl::Indices removed = *filter.getRemovedIndices();
  filter.setNegative(true);
  filter.filter(rest);

  pcl::Indices want_kept, want_rest;
  for (int i = 0; i < 200; ++i) ((*cloud)[i].label == 2 ? want_kept : want_rest).push_back(i);
  ASSERT_FALSE(want_kept.empty());
  EXPECT_EQ(kept, want_kept);
  EXPECT_EQ(removed, want_rest);
  EXPECT_EQ(rest, want_rest);
  EXPECT_EQ(*filter.getRemovedIndices(), want_kept);

  pcl::PointCloud<GaussianPoint> out;
  filter.setNegative(false);
  filter.filter(out);
  ASSERT_EQ(out.size(), want_kept.size());
  EXPECT_TRUE(bitwiseEqual(out[0], (*cloud)[want_kept[0]]));
}

TEST(ClassExtraction, RespectsSetIndicesAndWorksOnPlainLabelledClouds) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZRGBL>>();
  for (std::uint32_t l : {0u, 1u, 1u, 0u, 1u}) {
    pcl::PointXYZRGBL p;
    p.label = l;
    cloud->push_back(p);
  }
  filters::ClassExtraction<pcl::PointXYZRGBL> filter;
  filter.setInputCloud(cloud);
  filter.setIndices(std::make_shared<pcl::Indices>(pcl::Indices{0, 1, 2}));
  filter.setClassId(1);
  pcl::Indices kept;
  filter.filter(kept);
  EXPECT_EQ(kept, (pcl::Indices{1, 2}));
}

TEST(ClassExtraction, SelectsByNameOrSaysWhichNamesExist) {
  const std::vector<ClassInfo> classes = {{"road", {0, 0, 0}, ""}, {"tree", {0, 0, 0}, ""}};
  filters::ClassExtraction<GaussianPoint> filter;
  filter.setClassName("tree", classes);
  EXPECT_EQ(filter.getClassId(), 1u);
  try {
    filter.setClassName("water", classes);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.expected(), "one of: road, tree");
  }
}

}  // namespace
}  // namespace sadsplat
