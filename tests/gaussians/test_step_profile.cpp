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

TEST(StepProfile, AProfiledTrainingTimesEveryPhaseAndGivesTheSameModel) {
  const io::Scene scene =
      io::readSceneCache(std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache");
  gaussians::TrainConfig config;
  config.iterations = 12;
  config.feature_dim = 8;
  config.densify_from = 4;
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
  }
  EXPECT_TRUE(at::equal(plain.parameters().means, profiled.parameters().means));
}

}  // namespace
}  // namespace sadsplat
