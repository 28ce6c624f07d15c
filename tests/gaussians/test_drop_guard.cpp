// The trainer's side of a drop strategy's guard (drop_state.h): when the strategy is asked for a
// reading, and what a checkpoint keeps of the guard. The balanced rule's guard itself:
// tests/semantic_drop/test_drop_guard.cpp.
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "drop_state.h"
#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/drop_strategy.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/train_config.h"

namespace sadsplat {
namespace {

using gaussians::DropGuard;
using gaussians::DropState;
using gaussians::TrainConfig;

// Drop events (and guard readings) every `interval` iterations before the last; a reading sets
// the guard to (half its pressure, the reading, its iteration).
class EventsEvery : public gaussians::DropStrategy {
 public:
  EventsEvery(int interval, int iterations) : interval_(interval), iterations_(iterations) {}
  at::Tensor trainingGate(const at::Tensor&, int) const override { return {}; }
  at::Tensor evaluationGate(const at::Tensor&) const override { return {}; }
  at::Tensor regularisation(const at::Tensor&, int, const at::Tensor&) const override { return {}; }
  bool dropNow(int done) const override { return done % interval_ == 0 && done < iterations_; }
  bool guardReadsBefore(int done) const override { return dropNow(done); }
  void observeGuardReading(DropGuard& guard, int done, double mse) const override {
    guard = {guard.pressure / 2, mse, static_cast<double>(done)};
  }
  gaussians::DropDecision decide(const gaussians::DropInputs&, int) const override { return {}; }

 private:
  int interval_, iterations_;
};

TrainConfig guardConfig() {
  TrainConfig c;
  c.drop = gaussians::DropMode::kFull;
  c.iterations = 7000;
  c.drop_interval = 500;
  return c;
}

std::unique_ptr<DropState> guardOf(const TrainConfig& c) {
  auto state = std::make_unique<DropState>(c, c);
  state->setStrategy(std::make_shared<EventsEvery>(c.drop_interval, c.iterations));
  state->initialise(3, at::TensorOptions().dtype(at::kFloat));
  return state;
}

TEST(DropGuard, NoReadingInTheRecoveryPhaseOrWithoutAStrategy) {
  TrainConfig recovery = guardConfig();
  recovery.recovery_iterations = 1000;  // no gates, no events from 6000 on
  EXPECT_TRUE(guardOf(recovery)->guardProbeDue(5500));
  EXPECT_FALSE(guardOf(recovery)->guardProbeDue(6000));
  EXPECT_FALSE(guardOf(recovery)->guardProbeDue(5750));  // no event
  DropState none(recovery, recovery);
  none.initialise(3, at::TensorOptions().dtype(at::kFloat));
  EXPECT_FALSE(none.guardProbeDue(5500));
  none.observeGuardProbe(5500, 1.0);  // nothing to update
  EXPECT_EQ(none.pressure(), 1.0);
}

TEST(DropGuard, ACheckpointKeepsTheGuardAndAnOlderOneItsPressure) {
  auto state = guardOf(guardConfig());
  state->observeGuardProbe(500, 1.0);  // pressure 0.5, reading 1.0 at 500
  gaussians::TensorArchive archive;
  state->save(archive);
  const at::Tensor saved = archive.tensor("drop_guard", "ckpt.bin").contiguous();
  ASSERT_EQ(saved.numel(), 4);
  std::array<double, 4> packed{};
  std::memcpy(packed.data(), saved.data_ptr<std::int64_t>(), sizeof(double) * 4);
  EXPECT_EQ(packed, (std::array<double, 4>{0.5, 1.0, 500.0, DropGuard::kVersion}));

  auto resumed = guardOf(guardConfig());
  resumed->load(archive, "ckpt.bin", at::kCPU);
  EXPECT_EQ(resumed->pressure(), 0.5);
  resumed->observeGuardProbe(1000, 2.0);
  EXPECT_EQ(resumed->pressure(), 0.25);

  // The guard of older checkpoints (a count >= 0 in the last place) keeps its pressure.
  const std::vector<double> old_guard{0.5, 0.2, 1.3, 5.0};
  std::vector<std::int64_t> bits(4);
  std::memcpy(bits.data(), old_guard.data(), sizeof(double) * 4);
  archive.tensors["drop_guard"] = at::tensor(bits, at::kLong);
  auto old = guardOf(guardConfig());
  old->load(archive, "old.bin", at::kCPU);
  EXPECT_EQ(old->pressure(), 0.5);

  // A pressure outside (0, 1] is a damaged file.
  const std::vector<double> bad{1.5, -1, 0, -2};
  std::memcpy(bits.data(), bad.data(), sizeof(double) * 4);
  archive.tensors["drop_guard"] = at::tensor(bits, at::kLong);
  EXPECT_THROW(guardOf(guardConfig())->load(archive, "bad.bin", at::kCPU), Error);
}

}  // namespace
}  // namespace sadsplat
