// GaussianPoint as a PCL point type: registration, field layout and the PCL algorithms
// explicitly instantiated for it.
#include <gtest/gtest.h>
#include <pcl/common/io.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/random_sample.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/search/kdtree.h>

#include "sadsplat/common/gaussian_point.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

TEST(GaussianPoint, RegistersTheDocumentedFieldsInOrder) {
  std::vector<pcl::PCLPointField> fields;
  pcl::getFields<GaussianPoint>(fields);
  std::vector<std::pair<std::string, std::uint32_t>> got;
  for (const auto& f : fields) got.emplace_back(f.name, f.count);
  const std::vector<std::pair<std::string, std::uint32_t>> want = {
      {"x", 1},   {"y", 1},        {"z", 1},         {"nx", 1},         {"ny", 1},
      {"nz", 1},  {"f_dc", 3},     {"f_rest", 45},   {"opacity", 1},    {"scale", 3},
      {"rot", 4}, {"feature", 32}, {"log_alpha", 1}, {"confidence", 1}, {"label", 1}};
  EXPECT_EQ(got, want);
  EXPECT_EQ(fields.back().datatype, pcl::PCLPointField::UINT32);
}

TEST(GaussianPoint, DefaultIsANeutralUnlabelledGaussian) {
  const GaussianPoint p;
  EXPECT_EQ(p.x, 0.f);
  EXPECT_EQ(p.rot[0], 1.f);
  EXPECT_EQ(p.rot[1], 0.f);
  EXPECT_EQ(p.scale[2], 0.f);
  EXPECT_EQ(p.feature[31], 0.f);
  EXPECT_EQ(p.label, kUnlabelled);
}

TEST(GaussianPoint, BitwiseEqualSeesEveryField) {
  const auto cloud = test::randomGaussians(2, 3);
  GaussianPoint a = cloud[0];
  EXPECT_TRUE(bitwiseEqual(a, cloud[0]));
  a.feature[31] += 1.f;
  EXPECT_FALSE(bitwiseEqual(a, cloud[0]));
  a = cloud[0];
  a.label ^= 1u;
  EXPECT_FALSE(bitwiseEqual(a, cloud[0]));
}

TEST(GaussianPoint, KdTreeFlannFindsTheNearestCentres) {
  auto cloud = std::make_shared<pcl::PointCloud<GaussianPoint>>();
  for (int i = 0; i < 10; ++i) {
    GaussianPoint p;
    p.x = static_cast<float>(i);
    cloud->push_back(p);
  }
  pcl::KdTreeFLANN<GaussianPoint> tree;
  tree.setInputCloud(cloud);
  GaussianPoint query;
  query.x = 6.2f;
  pcl::Indices idx;
  std::vector<float> d2;
  ASSERT_EQ(tree.nearestKSearch(query, 2, idx, d2), 2);
  EXPECT_EQ(idx[0], 6);
  EXPECT_EQ(idx[1], 7);
  EXPECT_NEAR(d2[0], 0.04f, 1e-5f);

  pcl::search::KdTree<GaussianPoint> search;
  search.setInputCloud(cloud);
  EXPECT_EQ(search.radiusSearch(query, 1.5, idx, d2), 3);  // 5, 6, 7
}

TEST(GaussianPoint, ExtractIndicesKeepsAndRemovesExactly) {
  auto cloud = std::make_shared<pcl::PointCloud<GaussianPoint>>(test::randomGaussians(20, 1));
  auto indices = std::make_shared<pcl::Indices>(pcl::Indices{1, 4, 9});
  pcl::ExtractIndices<GaussianPoint> extract(true);
  extract.setInputCloud(cloud);
  extract.setIndices(indices);
  pcl::PointCloud<GaussianPoint> kept, rest;
  extract.filter(kept);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_TRUE(bitwiseEqual(kept[2], (*cloud)[9]));
  EXPECT_EQ(extract.getRemovedIndices()->size(), 17u);
  extract.setNegative(true);
  extract.filter(rest);
  EXPECT_EQ(rest.size(), 17u);
  EXPECT_TRUE(bitwiseEqual(rest[0], (*cloud)[0]));
}

TEST(GaussianPoint, VoxelGridMergesPointsOfOneVoxel) {
  auto cloud = std::make_shared<pcl::PointCloud<GaussianPoint>>();
  for (float x : {0.1f, 0.2f, 5.1f}) {
    GaussianPoint p;
    p.x = x;
    p.y = p.z = 0.5f;
    p.opacity = x;
    cloud->push_back(p);
  }
  pcl::VoxelGrid<GaussianPoint> grid;
  grid.setInputCloud(cloud);
  grid.setLeafSize(1.f, 1.f, 1.f);
  pcl::PointCloud<GaussianPoint> out;
  grid.filter(out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].x, 0.15f, 1e-6f);
  // PCL's CentroidPoint averages only the fields it knows (xyz here); the other fields of a
  // voxel's point are GaussianPoint's defaults. Documented in gaussian_point.h.
  EXPECT_EQ(out[0].opacity, 0.f);
  EXPECT_EQ(out[0].rot[0], 1.f);
}

TEST(GaussianPoint, RandomSampleIsSeeded) {
  auto cloud = std::make_shared<pcl::PointCloud<GaussianPoint>>(test::randomGaussians(100, 2));
  pcl::RandomSample<GaussianPoint> sample;
  sample.setInputCloud(cloud);
  sample.setSample(10);
  sample.setSeed(5);
  pcl::Indices a, b;
  sample.filter(a);
  sample.filter(b);
  EXPECT_EQ(a.size(), 10u);
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace sadsplat
