// The balanced drop rule (semantic_drop/drop_strategy.h): the guard's readings and what it
// compares, the cap on each event, and the L0 force in place of the loss term.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include <cstdint>
#include <limits>
#include <memory>

#include "sadsplat/gaussians/drop_strategy.h"
#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/semantic_drop/drop_strategy.h"

namespace sadsplat {
namespace {

using gaussians::TrainConfig;

// 7000 iterations, drop events every 500 from 500 (the L0 force's start), opacity resets after
// 3000 and 6000 up to densify_until 6000, no recovery.
TrainConfig guardConfig() {
  TrainConfig c;
  c.drop = gaussians::DropMode::kFull;
  c.drop_rule = gaussians::DropRule::kBalanced;
  c.iterations = 7000;
  c.drop_interval = 500;
  c.lambda_l0_from = 500;
  c.opacity_reset_interval = 3000;
  c.densify_until = 6000;
  c.drop_guard = 0.05;
  return c;
}

// The guard's state and the strategy that updates it.
struct Guarded {
  explicit Guarded(const TrainConfig& c) : rule(semantic_drop::makeDropStrategy(c)) {}
  bool readsBefore(int done) const { return rule->guardReadsBefore(done); }
  void observe(int done, double mse) { rule->observeGuardReading(guard, done, mse); }
  double pressure() const { return guard.pressure; }
  std::shared_ptr<const gaussians::DropStrategy> rule;
  gaussians::DropGuard guard;
};

TEST(DropGuard, ReadsBeforeEachDropEventOfTheBalancedRuleOnly) {
  const TrainConfig c = guardConfig();
  const Guarded state(c);
  EXPECT_TRUE(state.readsBefore(500));
  EXPECT_TRUE(state.readsBefore(6500));
  EXPECT_FALSE(state.readsBefore(750));   // no event
  EXPECT_FALSE(state.readsBefore(7000));  // no event after the last iteration

  TrainConfig late = c;
  late.lambda_l0_from = 3500;  // no event before the L0 force
  EXPECT_FALSE(Guarded(late).readsBefore(3000));
  EXPECT_TRUE(Guarded(late).readsBefore(3500));

  TrainConfig off = c;
  off.drop_guard = 0;
  EXPECT_FALSE(Guarded(off).readsBefore(500));
  TrainConfig paper = c;
  paper.drop_rule = gaussians::DropRule::kPaper;
  EXPECT_FALSE(Guarded(paper).readsBefore(500));
  Guarded unguarded(paper);  // the paper's rule has no guard: readings change nothing
  unguarded.observe(500, 1.0);
  unguarded.observe(1000, 9.0);
  EXPECT_EQ(unguarded.pressure(), 1.0);
  EXPECT_LT(unguarded.guard.lowest, 0);
}

TEST(DropGuard, HalvesThePressureWhileTheErrorStaysAboveItsLowestByMoreThanTheMargin) {
  Guarded state(guardConfig());
  EXPECT_EQ(state.pressure(), 1.0);
  state.observe(500, 1.00);  // the first reading: nothing to compare with
  EXPECT_EQ(state.pressure(), 1.0);
  state.observe(1000, 1.04);  // within 5 % of the lowest
  EXPECT_EQ(state.pressure(), 1.0);
  state.observe(1500, 0.90);  // lower: the new reference
  EXPECT_EQ(state.pressure(), 1.0);
  state.observe(2000, 0.96);  // 6.7 % above 0.90
  EXPECT_EQ(state.pressure(), 0.5);
  state.observe(2500, 0.95);  // still above 0.945: not won back
  EXPECT_EQ(state.pressure(), 0.25);
  state.observe(3000, 0.94);  // within the margin again
  EXPECT_EQ(state.pressure(), 0.25);
  // A non-finite reading is no reading.
  state.observe(3000, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(state.pressure(), 0.25);
}

TEST(DropGuard, AnOpacityResetStartsAFreshReference) {
  Guarded state(guardConfig());
  state.observe(2500, 1.0);
  // The reading of 3000 comes before that iteration's reset: compared as usual.
  state.observe(3000, 1.0);
  // The reset after 3000 lies between this reading and the last: the error may have doubled.
  state.observe(3500, 2.0);
  EXPECT_EQ(state.pressure(), 1.0);
  // From there on 2.0 is the reference.
  state.observe(4000, 2.2);
  EXPECT_EQ(state.pressure(), 0.5);
  // After densify_until (6000) the densification resets nothing: 6500 compares with 5500's 2.0.
  state.observe(5500, 2.0);
  EXPECT_EQ(state.pressure(), 0.5);
  state.observe(6000, 2.0);
  state.observe(6500, 4.0);  // the reset after 6000: fresh
  EXPECT_EQ(state.pressure(), 0.5);

  TrainConfig late_densify = guardConfig();
  late_densify.densify_until = 3499;  // the last reset after 3000: 6500 compares with 6000
  Guarded late(late_densify);
  late.observe(6000, 1.0);
  late.observe(6500, 1.2);
  EXPECT_EQ(late.pressure(), 0.5);
}

TEST(DropGuard, AnOlderCheckpointsGuardKeepsItsPressureAndStartsAFreshReading) {
  Guarded state(guardConfig());
  state.observe(500, 1.0);
  state.observe(1000, 1.2);  // pressure 0.5, reference 1.0
  Guarded resumed(guardConfig());
  resumed.guard = gaussians::DropGuard::unpacked(state.guard.packed());
  EXPECT_EQ(resumed.pressure(), 0.5);
  resumed.observe(1500, 1.06);  // above the saved reference 1.0 by 6 %
  EXPECT_EQ(resumed.pressure(), 0.25);

  // The guard of older checkpoints: pressure, the window's mean loss, the sum and the count of
  // the readings in the current window (a count >= 0 in the last place).
  Guarded old(guardConfig());
  old.guard = gaussians::DropGuard::unpacked({0.5, 0.2, 1.3, 5.0});
  EXPECT_EQ(old.pressure(), 0.5);
  old.observe(1500, 9.0);  // the first reading after the resume: nothing to compare
  EXPECT_EQ(old.pressure(), 0.5);
}

TEST(BalancedRule, CapsEachEventAtTheFractionTimesThePressureAndThePaperRuleNot) {
  TrainConfig c = guardConfig();
  c.drop_max_fraction = 0.15;
  const auto rule = semantic_drop::makeDropStrategy(c);
  gaussians::DropGuard guard;
  EXPECT_EQ(rule->maxRemoved(1000, guard), 150);
  guard.pressure = 0.5;
  EXPECT_EQ(rule->maxRemoved(1000, guard), 75);
  EXPECT_EQ(rule->maxRemoved(999, guard), 74);  // floor(74.925)
  c.drop_rule = gaussians::DropRule::kPaper;
  EXPECT_EQ(semantic_drop::makeDropStrategy(c)->maxRemoved(1000, guard), -1);
}

TEST(BalancedRule, NoDropEventBeforeTheL0ForceStarts) {
  TrainConfig c = guardConfig();
  c.lambda_l0_from = 1500;
  EXPECT_FALSE(semantic_drop::makeDropStrategy(c)->dropNow(1000));
  EXPECT_TRUE(semantic_drop::makeDropStrategy(c)->dropNow(1500));
  c.drop_rule = gaussians::DropRule::kPaper;  // the paper's rule drops from the start
  EXPECT_TRUE(semantic_drop::makeDropStrategy(c)->dropNow(1000));
}

// The force on the reached Gaussians is l0_strength x pressure x ramp x (mean |grad| over them)
// x dP / (mean dP over them); by hand for two reached Gaussians of equal log_alpha.
TEST(BalancedRule, TheL0ForceScalesWithStrengthPressureAndRampOnReachedGaussiansOnly) {
  TrainConfig c = guardConfig();
  c.lambda_l0_from = 500;
  c.lambda_l0_ramp = 4;  // iteration 500: 1/4 of the strength
  c.l0_strength = 2.0;
  const at::Tensor log_alpha = at::zeros({3});
  const at::Tensor opacity_grad = at::tensor({1.0f, 0.0f, -1.0f});  // 1 not reached
  const at::Tensor start = at::tensor({0.4f, 7.0f, -0.2f});
  gaussians::DropGuard guard;
  guard.pressure = 0.5;
  const auto forceOf = [&](const TrainConfig& config, int it) {
    at::Tensor grad = start.clone();
    semantic_drop::makeDropStrategy(config)->addL0Force(grad, log_alpha, opacity_grad,
                                                        at::Tensor(), it, guard);
    return grad - start;
  };
  // Equal dP on 0 and 2: each gets strength x pressure x ramp x mean |grad| = 2 x 0.5 x 0.25 x 0.3.
  const at::Tensor f = forceOf(c, 500);
  EXPECT_NEAR(f[0].item<double>(), 0.075, 1e-6);
  EXPECT_EQ(f[1].item<double>(), 0.0);
  EXPECT_NEAR(f[2].item<double>(), 0.075, 1e-6);
  EXPECT_NEAR(forceOf(c, 503)[0].item<double>(), 0.3, 1e-6);  // the ramp's end
  EXPECT_EQ(forceOf(c, 499).abs().sum().item<double>(), 0.0);  // before the L0 force starts
  TrainConfig paper = c;
  paper.drop_rule = gaussians::DropRule::kPaper;  // a loss term, no force
  EXPECT_EQ(forceOf(paper, 600).abs().sum().item<double>(), 0.0);
  TrainConfig semantic = c;
  semantic.drop = gaussians::DropMode::kSemantic;  // no gates: nothing to push
  EXPECT_EQ(forceOf(semantic, 600).abs().sum().item<double>(), 0.0);
}

}  // namespace
}  // namespace sadsplat
