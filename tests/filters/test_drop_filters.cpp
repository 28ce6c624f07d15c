// The PCL drop filters (torch-free): the drop rate P_drop of the paper's rule, seeded, and the
// shared pcl::FilterIndices behaviour (removed indices, negative).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "sadsplat/filters/drop_filters.h"

namespace sadsplat {
namespace filters {
namespace {

pcl::PointCloud<GaussianPoint>::Ptr cloudWith(int n, float log_alpha, float confidence) {
  auto cloud = std::make_shared<pcl::PointCloud<GaussianPoint>>();
  cloud->resize(n);
  for (int i = 0; i < n; ++i) {
    (*cloud)[i].x = static_cast<float>(i);
    (*cloud)[i].log_alpha = log_alpha;
    (*cloud)[i].confidence = confidence;
  }
  return cloud;
}

TEST(DropFilters, RemoveAtTheExpectedRateAndBehaveLikePclFilters) {
  // Choose log_alpha so that P_learned = 0.5; confidence 0.4 -> P_drop = 1.2 * 0.6 * 0.5 = 0.36.
  const HardConcreteParams hc;
  const double la = hc.beta * std::log((1.0 / 12) / (11.0 / 12));  // P_nonzero = 0.5
  const auto cloud = cloudWith(40000, static_cast<float>(la), 0.4f);
  SemanticDrop<GaussianPoint> drop(true);
  drop.setInputCloud(cloud);
  drop.setBaseRate(1.2);
  drop.setSeed(7);
  EXPECT_NEAR(drop.dropProbability((*cloud)[0]), 0.36, 1e-6);
  pcl::Indices kept, kept_again, removed_set;
  drop.filter(kept);
  const pcl::Indices removed = *drop.getRemovedIndices();
  EXPECT_NEAR(removed.size() / 40000.0, 0.36, 0.01);
  drop.filter(kept_again);
  EXPECT_EQ(kept, kept_again);  // seeded
  EXPECT_EQ(kept.size() + removed.size(), 40000u);
  std::set<int> all(kept.begin(), kept.end());
  for (int i : removed)
    EXPECT_TRUE(all.insert(i).second) << "index " << i << " both kept and removed";
  drop.setNegative(true);
  drop.filter(removed_set);
  EXPECT_EQ(removed_set, removed);

  ConfidenceDrop<GaussianPoint> semantic_only;
  semantic_only.setInputCloud(cloud);
  EXPECT_NEAR(semantic_only.dropProbability((*cloud)[0]), 0.6, 1e-6);
  HardConcreteDrop<GaussianPoint> structure_only;
  structure_only.setInputCloud(cloud);
  structure_only.setBaseRate(3.0);
  EXPECT_NEAR(structure_only.dropProbability((*cloud)[0]), 1.0, 1e-9);  // clamped
  pcl::PointCloud<GaussianPoint> out;
  structure_only.filter(out);
  EXPECT_EQ(out.size(), 0u);
}

// The closed form at a few points: P_nonzero(0) = sigmoid(-beta logit(1/12)) and the rule's
// clamping and switches.
TEST(HardConcreteMath, ProbabilityAndDropRuleByHand) {
  const HardConcreteParams hc;
  const double expected = 1.0 / (1.0 + std::exp(hc.beta * std::log((1.0 / 12) / (11.0 / 12))));
  EXPECT_NEAR(probabilityNonZero(0.0, hc), expected, 1e-12);
  EXPECT_NEAR(dropProbability(1.0, 0.25, 0.0, true, true, hc), 0.75 * (1 - expected), 1e-12);
  EXPECT_EQ(dropProbability(1.0, 0.25, 0.0, false, false, hc), 1.0);
  EXPECT_EQ(dropProbability(-1.0, 0.25, 0.0, true, true, hc), 0.0);
  EXPECT_EQ(dropProbability(1.0, 2.0, 0.0, true, false, hc), 0.0);  // confidence clamped to 1
}

}  // namespace
}  // namespace filters
}  // namespace sadsplat
