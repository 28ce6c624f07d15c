// The balanced drop rule's quality guard (drop_state.h): when it reads, what it compares, and
// what a checkpoint keeps of it.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "drop_state.h"
#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/drop_strategy.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/train_config.h"

namespace sadsplat {
namespace {

using gaussians::DropState;
using gaussians::TrainConfig;

// Drop events every `interval` iterations before the last; no gates, no decisions of its own.
class EventsEvery : public gaussians::DropStrategy {
 public:
  EventsEvery(int interval, int iterations) : interval_(interval), iterations_(iterations) {}
  at::Tensor trainingGate(const at::Tensor&, int) const override { return {}; }
  at::Tensor evaluationGate(const at::Tensor&) const override { return {}; }
  at::Tensor regularisation(const at::Tensor&, int, const at::Tensor&) const override { return {}; }
  bool dropNow(int done) const override { return done % interval_ == 0 && done < iterations_; }
  gaussians::DropDecision decide(const gaussians::DropInputs&, int) const override { return {}; }

 private:
  int interval_, iterations_;
};

// 7000 iterations, drop events every 500 from 500 (the L0 force's start), opacity resets after
// 3000 and 6000 up to densify_until 6000, no recovery.
TrainConfig guardConfig() {
  TrainConfig c;
  c.drop = "full";
  c.drop_rule = "balanced";
  c.iterations = 7000;
  c.drop_interval = 500;
  c.lambda_l0_from = 500;
  c.opacity_reset_interval = 3000;
  c.densify_until = 6000;
  c.drop_guard = 0.05;
  return c;
}

std::unique_ptr<DropState> guardOf(const TrainConfig& c) {
  auto state = std::make_unique<DropState>(c, c, c);
  state->setStrategy(std::make_shared<EventsEvery>(c.drop_interval, c.iterations));
  state->initialise(3, at::TensorOptions().dtype(at::kFloat));
  return state;
}

TEST(DropGuard, ReadsBeforeEachDropEventOfTheBalancedRuleOnly) {
  const TrainConfig c = guardConfig();
  auto state = guardOf(c);
  EXPECT_TRUE(state->guardProbeDue(500));
  EXPECT_TRUE(state->guardProbeDue(6500));
  EXPECT_FALSE(state->guardProbeDue(750));   // no event
  EXPECT_FALSE(state->guardProbeDue(7000));  // no event after the last iteration

  TrainConfig late = c;
  late.lambda_l0_from = 3500;  // no event before the L0 force
  EXPECT_FALSE(guardOf(late)->guardProbeDue(3000));
  EXPECT_TRUE(guardOf(late)->guardProbeDue(3500));

  TrainConfig recovery = c;
  recovery.recovery_iterations = 1000;  // no gates, no events from 6000 on
  EXPECT_TRUE(guardOf(recovery)->guardProbeDue(5500));
  EXPECT_FALSE(guardOf(recovery)->guardProbeDue(6000));

  TrainConfig off = c;
  off.drop_guard = 0;
  EXPECT_FALSE(guardOf(off)->guardProbeDue(500));
  TrainConfig paper = c;
  paper.drop_rule = "paper";
  EXPECT_FALSE(guardOf(paper)->guardProbeDue(500));
}

TEST(DropGuard, HalvesThePressureWhileTheErrorStaysAboveItsLowestByMoreThanTheMargin) {
  auto state = guardOf(guardConfig());
  EXPECT_EQ(state->pressure(), 1.0);
  state->observeGuardProbe(500, 1.00);  // the first reading: nothing to compare with
  EXPECT_EQ(state->pressure(), 1.0);
  state->observeGuardProbe(1000, 1.04);  // within 5 % of the lowest
  EXPECT_EQ(state->pressure(), 1.0);
  state->observeGuardProbe(1500, 0.90);  // lower: the new reference
  EXPECT_EQ(state->pressure(), 1.0);
  state->observeGuardProbe(2000, 0.96);  // 6.7 % above 0.90
  EXPECT_EQ(state->pressure(), 0.5);
  state->observeGuardProbe(2500, 0.95);  // still above 0.945: not won back
  EXPECT_EQ(state->pressure(), 0.25);
  state->observeGuardProbe(3000, 0.94);  // within the margin again
  EXPECT_EQ(state->pressure(), 0.25);
  // A non-finite reading is no reading.
  state->observeGuardProbe(3000, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(state->pressure(), 0.25);
}

TEST(DropGuard, AnOpacityResetStartsAFreshReference) {
  auto state = guardOf(guardConfig());
  state->observeGuardProbe(2500, 1.0);
  // The reading of 3000 comes before that iteration's reset: compared as usual.
  state->observeGuardProbe(3000, 1.0);
  // The reset after 3000 lies between this reading and the last: the error may have doubled.
  state->observeGuardProbe(3500, 2.0);
  EXPECT_EQ(state->pressure(), 1.0);
  // From there on 2.0 is the reference.
  state->observeGuardProbe(4000, 2.2);
  EXPECT_EQ(state->pressure(), 0.5);
  // After densify_until (6000) the densification resets nothing: 6500 compares with 5500's 2.0.
  state->observeGuardProbe(5500, 2.0);
  EXPECT_EQ(state->pressure(), 0.5);
  state->observeGuardProbe(6000, 2.0);
  state->observeGuardProbe(6500, 4.0);  // the reset after 6000: fresh
  EXPECT_EQ(state->pressure(), 0.5);

  TrainConfig late_densify = guardConfig();
  late_densify.densify_until = 3499;  // the last reset after 3000: 6500 compares with 6000
  auto late = guardOf(late_densify);
  late->observeGuardProbe(6000, 1.0);
  late->observeGuardProbe(6500, 1.2);
  EXPECT_EQ(late->pressure(), 0.5);
}

TEST(DropGuard, ACheckpointKeepsTheGuardAndAnOlderOneStartsAFreshReading) {
  auto state = guardOf(guardConfig());
  state->observeGuardProbe(500, 1.0);
  state->observeGuardProbe(1000, 1.2);  // pressure 0.5, reference 1.0
  gaussians::TensorArchive archive;
  state->save(archive);

  auto resumed = guardOf(guardConfig());
  resumed->load(archive, "ckpt.bin", at::kCPU);
  EXPECT_EQ(resumed->pressure(), 0.5);
  resumed->observeGuardProbe(1500, 1.06);  // above the saved reference 1.0 by 6 %
  EXPECT_EQ(resumed->pressure(), 0.25);

  // The guard of older checkpoints: pressure, the window's mean loss, the sum and the count of
  // the readings in the current window (a count >= 0 in the last place).
  const std::vector<double> old_guard{0.5, 0.2, 1.3, 5.0};
  std::vector<std::int64_t> bits(4);
  std::memcpy(bits.data(), old_guard.data(), sizeof(double) * 4);
  archive.tensors["drop_guard"] = at::tensor(bits, at::kLong);
  auto old = guardOf(guardConfig());
  old->load(archive, "old.bin", at::kCPU);
  EXPECT_EQ(old->pressure(), 0.5);
  old->observeGuardProbe(1500, 9.0);  // the first reading after the resume: nothing to compare
  EXPECT_EQ(old->pressure(), 0.5);

  // A pressure outside (0, 1] is a damaged file.
  const std::vector<double> bad{1.5, -1, 0, -2};
  std::memcpy(bits.data(), bad.data(), sizeof(double) * 4);
  archive.tensors["drop_guard"] = at::tensor(bits, at::kLong);
  EXPECT_THROW(guardOf(guardConfig())->load(archive, "bad.bin", at::kCPU), Error);
}

}  // namespace
}  // namespace sadsplat
