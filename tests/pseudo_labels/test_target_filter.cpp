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
