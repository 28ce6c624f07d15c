// The step profile: phases accumulate their own time, the table lists them in first-use order,
// and a profiled training phases every step without changing its result.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "sadsplat/gaussians/step_profile.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/scene_cache.h"

namespace sadsplat {
namespace {

using gaussians::StepProfile;

TEST(StepProfile, EachPhaseGetsTheTimeUntilTheNextOne) {
  StepProfile profile(at::Device(at::kCPU));
  profile.enter("a");
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  profile.enter("b");
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  profile.enter("a");
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  profile.leave();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // outside any phase
  profile.countIteration();
  EXPECT_GE(profile.seconds("a"), 0.060);
  EXPECT_LT(profile.seconds("a"), 0.060 + 0.050);
  EXPECT_GE(profile.seconds("b"), 0.010);
  EXPECT_LT(profile.seconds("b"), 0.030);
  EXPECT_EQ(profile.seconds("never"), 0.0);
  EXPECT_DOUBLE_EQ(profile.totalSeconds(), profile.seconds("a") + profile.seconds("b"));
  const std::string table = profile.table();
  EXPECT_LT(table.find("| a |"), table.find("| b |"));
  EXPECT_NE(table.find("(1 iterations)"), std::string::npos);
}

TEST(StepProfile, NestedPhasesKeepTheirOwnTimeAndAddUpToTheTotal) {
  StepProfile profile(at::Device(at::kCPU));
  {
    // No active profile: a ScopedPhase records nothing.
    const gaussians::ScopedPhase ignored("nowhere");
  }
  const gaussians::ActiveProfileScope active(&profile);
  {
    const gaussians::ScopedPhase outside("outside");  // no open phase: nothing either
  }
  profile.enter("outer");
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  {
    const gaussians::ScopedPhase inner("inner");
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    {
      const gaussians::ScopedPhase deepest("deepest");
      std::this_thread::sleep_for(std::chrono::milliseconds(60));
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  profile.leave();
  EXPECT_EQ(gaussians::activeProfile(), &profile);
  // Exclusive times: counting a nested phase in its parent as well would add >= 60 ms.
  EXPECT_GE(profile.seconds("outer"), 0.040);
  EXPECT_LT(profile.seconds("outer"), 0.040 + 0.040);
  EXPECT_GE(profile.seconds("outer / inner"), 0.020);
  EXPECT_LT(profile.seconds("outer / inner"), 0.020 + 0.040);
  EXPECT_GE(profile.seconds("outer / inner / deepest"), 0.060);
  EXPECT_EQ(profile.seconds("nowhere"), 0.0);
  EXPECT_EQ(profile.seconds("outside"), 0.0);
  EXPECT_DOUBLE_EQ(profile.totalSeconds(), profile.seconds("outer") +
                                               profile.seconds("outer / inner") +
                                               profile.seconds("outer / inner / deepest"));
  EXPECT_EQ(profile.peakAllocatedBytes("outer"), 0);  // CPU: no device memory
  const std::string table = profile.table();
  EXPECT_NE(table.find("| outer / inner / deepest |"), std::string::npos);
  EXPECT_EQ(table.find("peak allocated"), std::string::npos);
}

TEST(StepProfile, EachPhaseCountsItsOwnOperatorCallsOnceWhateverTheNumberOfProfiles) {
  StepProfile profile(at::Device(at::kCPU), StepProfile::Clock::kHost);
  StepProfile other(at::Device(at::kCPU));  // a second live profile must not double the count
  const at::Tensor x = at::ones({4});
  profile.enter("three adds");
  at::Tensor y = x;
  for (int i = 0; i < 3; ++i) y = at::add(y, x);
  profile.enter("no operator");
  std::this_thread::sleep_for(std::chrono::milliseconds(1));
  profile.enter("outer");
  {
    const gaussians::ActiveProfileScope active(&profile);
    const gaussians::ScopedPhase inner("inner");
    y = at::mul(y, x);
  }
  y = at::sub(y, x);
  y = at::sub(y, x);
  profile.leave();
  profile.countIteration();
  EXPECT_EQ(profile.operatorCalls("three adds"), 3);
  EXPECT_EQ(profile.operatorCalls("no operator"), 0);
  EXPECT_EQ(profile.operatorCalls("outer / inner"), 1);
  EXPECT_EQ(profile.operatorCalls("outer"), 2);  // its nested phase's call not counted twice
  EXPECT_EQ(y[0].item<float>(), 2.0f);           // (1 + 3) * 1 - 2
  EXPECT_NE(profile.table().find("| three adds | "), std::string::npos);
  EXPECT_NE(profile.table().find(" | 3.0 |"), std::string::npos);
}

TEST(StepProfile, TheOperatorTableNamesEachPhasesOperatorsPerIteration) {
  StepProfile profile(at::Device(at::kCPU), StepProfile::Clock::kHost);
  const at::Tensor x = at::ones({4});
  at::Tensor y = x;
  {
    const gaussians::ActiveProfileScope active(&profile);
    for (int iteration = 0; iteration < 2; ++iteration) {
      profile.enter("adds");
      for (int i = 0; i < 3; ++i) y = at::add(y, x);
      profile.enter("outer");
      {
        const gaussians::ScopedPhase inner("inner");
        y = at::mul(y, x);
      }
      profile.leave();
      profile.countIteration();
    }
  }
  y = at::sub(y, x);  // no active profile: not in the table
  const std::string table = profile.operatorTable();
  EXPECT_NE(table.find("**adds**: 3.0 calls per iteration"), std::string::npos) << table;
  EXPECT_NE(table.find("- 3.00 `aten::add`"), std::string::npos) << table;
  EXPECT_NE(table.find("**outer / inner**: 1.0 calls per iteration"), std::string::npos) << table;
  EXPECT_NE(table.find("- 1.00 `aten::mul`"), std::string::npos) << table;
  EXPECT_EQ(table.find("aten::sub"), std::string::npos) << table;
  EXPECT_EQ(table.find("**outer**"), std::string::npos) << table;  // no call of its own
}

TEST(StepProfile, TheActiveProfileScopeRestoresThePreviousOne) {
  StepProfile a(at::Device(at::kCPU)), b(at::Device(at::kCPU));
  EXPECT_EQ(gaussians::activeProfile(), nullptr);
  {
    const gaussians::ActiveProfileScope first(&a);
    {
      const gaussians::ActiveProfileScope second(&b);
      EXPECT_EQ(gaussians::activeProfile(), &b);
    }
    EXPECT_EQ(gaussians::activeProfile(), &a);
  }
  EXPECT_EQ(gaussians::activeProfile(), nullptr);
}

TEST(StepProfile, AProfiledTrainingTimesEveryPhaseAndGivesTheSameModel) {
  const io::Scene scene =
      io::readSceneCache(std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache");
  gaussians::TrainConfig config;
  config.iterations = 12;
  config.feature_dim = 8;
  config.densify_from = 4;
  config.densify_until = 6;  // one densification round, at iteration 5
  config.densify_interval = 5;
  config.checkpoint_interval = 0;
  gaussians::Trainer plain(scene, config), profiled(scene, config);
  auto profile = std::make_shared<StepProfile>(at::Device(at::kCPU));
  profiled.setProfile(profile);
  for (int i = 0; i < config.iterations; ++i) {
    const auto a = plain.step();
    const auto b = profiled.step();
    ASSERT_EQ(a.loss, b.loss) << "iteration " << i;
  }
  EXPECT_EQ(profile->iterations(), config.iterations);
  for (const char* phase : {"render forward", "losses forward", "backward", "optimiser",
                            "densify, prune, reset", "loss values to host"}) {
    EXPECT_GT(profile->seconds(phase), 0.0) << phase;
    EXPECT_GT(profile->operatorCalls(phase), 0) << phase;
  }
  // The rasterizer's steps, nested in the trainer's phases (the CPU backward runs in this thread).
  for (const char* phase : {"render forward / project", "render forward / SH",
                            "render forward / rasterize", "render forward / rasterize / binning",
                            "backward / rasterize backward", "backward / project backward"}) {
    EXPECT_GT(profile->seconds(phase), 0.0) << phase;
  }
  EXPECT_EQ(gaussians::activeProfile(), nullptr);  // step() restored it
  EXPECT_TRUE(at::equal(plain.parameters().means, profiled.parameters().means));
}

}  // namespace
}  // namespace sadsplat
