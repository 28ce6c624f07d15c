#include <gtest/gtest.h>

#include <cmath>

#include "sadsplat/pseudo_labels/target_filter.h"

namespace sp = sadsplat::pseudo_labels;

TEST(TargetFilter, MeasuresOfOneTarget) {
  const float s[3] = {0.7f, 0.2f, 0.1f};
  const sp::TargetMeasures m = sp::measureTarget(s, 3);
  EXPECT_NEAR(m.top1, 0.7, 1e-7);
  EXPECT_NEAR(m.delta_top, 0.5, 1e-7);
  EXPECT_NEAR(m.entropy, -(0.7 * std::log(0.7) + 0.2 * std::log(0.2) + 0.1 * std::log(0.1)), 1e-6);
  const sp::TargetMeasures l = sp::measureTarget(s, 3, sp::ScoreScale::kLogOdds);
  EXPECT_NEAR(l.top1, std::log(0.7 / 0.3), 1e-6);
  EXPECT_NEAR(l.delta_top, std::log(0.7 / 0.2), 1e-6);
  EXPECT_NEAR(l.entropy, m.entropy, 1e-9);
}

TEST(TargetFilter, EntropyNormalisesScoresAndHandlesAllZero) {
  const float s[2] = {2.0f, 2.0f};
  EXPECT_NEAR(sp::measureTarget(s, 2).entropy, std::log(2.0), 1e-9);
  const float z[4] = {0, 0, 0, 0};
  EXPECT_NEAR(sp::measureTarget(z, 4).entropy, std::log(4.0), 1e-9);
}

// Four targets whose measures are set by hand; thresholds and decisions computed by hand:
// TOP1 = {0.9, 0.5, 0.6, 0.95}: mean 0.7375, population std 0.19162 -> threshold 0.92912
// dTOP = {0.8, 0.1, 0.3, 0.9}:  mean 0.525,  std 0.33448             -> threshold 0.85948
// entropy = {0.2, 1.0, 0.8, 0.1}: mean 0.525, std 0.38324             -> threshold 0.90824
// Kept: only target 3 (0.95 > 0.929, 0.9 > 0.859, 0.1 < 0.908). Target 0 fails TOP1 and dTOP.
TEST(TargetFilter, HandComputedKeepDecisions) {
  std::vector<sp::TargetMeasures> t = {
      {0.9, 0.8, 0.2}, {0.5, 0.1, 1.0}, {0.6, 0.3, 0.8}, {0.95, 0.9, 0.1}};
  const sp::TargetStatistics s = sp::targetStatistics(t);
  EXPECT_NEAR(s.top1_mean, 0.7375, 1e-12);
  EXPECT_NEAR(s.top1_std, 0.191621, 1e-6);
  EXPECT_NEAR(s.delta_top_mean, 0.525, 1e-12);
  EXPECT_NEAR(s.delta_top_std, 0.334477, 1e-6);
  EXPECT_NEAR(s.entropy_mean, 0.525, 1e-12);
  EXPECT_NEAR(s.entropy_std, 0.383243, 1e-6);
  EXPECT_EQ(s.count, 4u);
  EXPECT_FALSE(sp::keepTarget(t[0], s));
  EXPECT_FALSE(sp::keepTarget(t[1], s));
  EXPECT_FALSE(sp::keepTarget(t[2], s));
  EXPECT_TRUE(sp::keepTarget(t[3], s));
  // With k = 0 (thresholds at the means) target 0 passes all three as well.
  EXPECT_TRUE(sp::keepTarget(t[0], s, 0.0));
  EXPECT_FALSE(sp::keepTarget(t[2], s, 0.0));
}

TEST(TargetFilter, EachConditionAloneCanReject) {
  sp::TargetStatistics s;
  s.top1_mean = 0.5, s.delta_top_mean = 0.5, s.entropy_mean = 0.5;
  EXPECT_TRUE(sp::keepTarget({0.6, 0.6, 0.4}, s));
  EXPECT_FALSE(sp::keepTarget({0.5, 0.6, 0.4}, s));  // TOP1 not strictly above
  EXPECT_FALSE(sp::keepTarget({0.6, 0.4, 0.4}, s));  // dTOP
  EXPECT_FALSE(sp::keepTarget({0.6, 0.6, 0.5}, s));  // entropy not strictly below
}

// Class-balanced statistics, by hand. Seven targets (TOP1, dTOP, entropy, TOP1 class):
//   class 0: (10, 9, 0.1) (12, 11, 0.2) (14, 13, 0.05)
//   class 1: (2, 1, 0.5)  (3, 2, 0.4)   (7, 6, 0.2)
//   class 2: (5, 4, 0.3)  -- fewer than min_targets = 2: gets the pooled statistics
// Pooled: TOP1 mean 7.5714 std 4.2378 -> 11.809; dTOP 6.5714 / 4.2378 -> 10.809;
//   entropy 0.25 / 0.14880 -> 0.39880: keeps (12, 11, 0.2) and (14, 13, 0.05), no class-1 target.
// Class 0: TOP1 12 / 1.6330 -> 13.633; dTOP 11 / 1.6330 -> 12.633; entropy 0.11667 / 0.062361
//   -> 0.17903: keeps (14, 13, 0.05) only.
// Class 1: TOP1 4 / 2.1602 -> 6.1602; dTOP 3 / 2.1602 -> 5.1602; entropy 0.36667 / 0.12472
//   -> 0.49139: keeps (7, 6, 0.2).
TEST(TargetFilter, ClassBalancedStatisticsKeepTheBestOfEachClass) {
  const std::vector<sp::TargetMeasures> t = {{10, 9, 0.1, 0}, {12, 11, 0.2, 0}, {14, 13, 0.05, 0},
                                             {2, 1, 0.5, 1},  {3, 2, 0.4, 1},   {7, 6, 0.2, 1},
                                             {5, 4, 0.3, 2}};
  const sp::TargetStatistics pooled = sp::targetStatistics(t);
  EXPECT_NEAR(pooled.top1_mean + pooled.top1_std, 11.8092, 1e-4);
  EXPECT_NEAR(pooled.entropy_mean + pooled.entropy_std, 0.39880, 1e-5);
  const std::vector<sp::TargetStatistics> per_class = sp::classStatistics(t, 3, 2);
  ASSERT_EQ(per_class.size(), 3u);
  EXPECT_EQ(per_class[0].count, 3u);
  EXPECT_NEAR(per_class[0].top1_mean + per_class[0].top1_std, 13.6330, 1e-4);
  EXPECT_NEAR(per_class[0].entropy_mean + per_class[0].entropy_std, 0.17903, 1e-5);
  EXPECT_NEAR(per_class[1].top1_mean + per_class[1].top1_std, 6.16025, 1e-5);
  EXPECT_NEAR(per_class[1].delta_top_mean + per_class[1].delta_top_std, 5.16025, 1e-5);
  EXPECT_NEAR(per_class[1].entropy_mean + per_class[1].entropy_std, 0.49139, 1e-5);
  EXPECT_EQ(per_class[2].count, 7u);  // the pooled statistics
  const std::vector<bool> expect_pooled = {false, true, true, false, false, false, false};
  const std::vector<bool> expect_per_class = {false, false, true, false, false, true, false};
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(sp::keepTarget(t[i], pooled), expect_pooled[i]) << i;
    EXPECT_EQ(sp::keepTarget(t[i], per_class[t[i].top_class]), expect_per_class[i]) << i;
  }
}

TEST(TargetFilter, TopClassIsTheArgmax) {
  const float scores[4] = {0.1f, 0.6f, 0.25f, 0.05f};
  EXPECT_EQ(sp::measureTarget(scores, 4).top_class, 1);
  const float none[2] = {0.0f, 0.0f};
  EXPECT_EQ(sp::measureTarget(none, 2).top_class, -1);
}
