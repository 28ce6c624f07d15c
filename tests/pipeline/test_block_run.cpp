// `sadsplat train --blocks`: the scene trained block by block and merged into one run that holds
// each block's Gaussians of its own cell once, evaluates like any run, resumes by keeping the
// finished blocks, and trains its blocks on two Gloo ranks as in one process.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/memory_estimate.h"
#include "sadsplat/geo/block_partition.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/pipeline/block_run.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using test::kCli;
using test::kTinySceneCache;

// Gaussians of `ply` per cell of the partition.
std::vector<int> perCell(const geo::BlockPartition& p, const std::string& ply) {
  std::vector<int> n(p.blocks.size(), 0);
  for (const auto& g : io::readGaussianPly(ply)) ++n[p.blockOf({g.x, g.y, g.z})];
  return n;
}

const std::string kTrain = " train " + kTinySceneCache + " --iterations 30";
const std::string kBlockRun = kTrain + " --blocks 2";

TEST(BlockRun, TheMergedModelHoldsEachBlocksOwnCellOnceAndResumes) {
  test::TempDir dir;
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + kBlockRun + " --out " + dir.file("run"), &out), 0) << out;
  EXPECT_NE(out.find("block 2/2"), std::string::npos) << out;
  geo::BlockOptions options;
  options.blocks = 2;
  const io::Scene scene = io::readSceneCache(kTinySceneCache);
  const geo::BlockPartition p = geo::partitionScene(scene, options, kTinySceneCache);
  ASSERT_EQ(p.blocks.size(), 2u);
  const auto recorded = nlohmann::json::parse(test::readFile(dir.file("run/blocks.json")));
  ASSERT_EQ(recorded["blocks"].size(), 2u);
  const std::vector<int> merged = perCell(p, dir.file("run/model.ply"));
  int total = 0;
  for (const geo::Block& b : p.blocks) {
    ASSERT_FALSE(b.views.empty());
    EXPECT_EQ(recorded["blocks"][b.index]["views"].size(), b.views.size());
    const std::string block_model = dir.file("run/blocks/b00" + std::to_string(b.index)) +
                                    "/model.ply";
    const std::vector<int> own = perCell(p, block_model);
    // The merge keeps exactly the block's Gaussians inside its cell, and it had others outside.
    EXPECT_EQ(merged[b.index], own[b.index]) << b.index;
    EXPECT_GT(static_cast<int>(io::readGaussianPly(block_model).size()), own[b.index]);
    EXPECT_GT(own[b.index], 0);
    total += own[b.index];
  }
  EXPECT_EQ(static_cast<int>(io::readGaussianPly(dir.file("run/model.ply")).size()), total);
  ASSERT_EQ(test::runCommand(kCli + " info " + dir.file("run"), &out), 0) << out;
  EXPECT_NE(out.find("blocks: 1 x 2 grid"), std::string::npos) << out;
  // A damaged blocks.json is a clear error naming it.
  const std::string partition = test::readFile(dir.file("run/blocks.json"));
  test::writeFile(dir.file("run/blocks.json"), "{\"rows\": 1}");
  EXPECT_EQ(test::runCommand(kCli + " info " + dir.file("run"), &out), 1);
  EXPECT_NE(out.find("blocks.json"), std::string::npos) << out;
  test::writeFile(dir.file("run/blocks.json"), partition);
  // Resuming keeps the finished blocks and merges them into the same model.
  const std::string model = test::readFile(dir.file("run/model.ply"));
  ASSERT_EQ(test::runCommand(kCli + kBlockRun + " --resume --out " + dir.file("run"), &out), 0)
      << out;
  EXPECT_NE(out.find("finished before, kept"), std::string::npos) << out;
  EXPECT_EQ(out.find("): training"), std::string::npos) << out;
  EXPECT_EQ(test::readFile(dir.file("run/model.ply")), model);
}

// A block run leaves the pixels in the cache and every block's training reads its views from the
// file (held on the device, or with --stream-views read again for each step): the same merged
// model either way (the CPU: bit for bit).
TEST(BlockRun, ViewsStreamedFromTheCacheTrainTheSameBlocks) {
  test::TempDir dir;
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + kBlockRun + " --out " + dir.file("held"), &out), 0) << out;
  ASSERT_EQ(
      test::runCommand(kCli + kBlockRun + " --stream-views --out " + dir.file("streamed"), &out),
      0)
      << out;
  EXPECT_NE(out.find("one at a time as the training needs them"), std::string::npos) << out;
  EXPECT_NE(out.find("peak host memory"), std::string::npos) << out;
  EXPECT_TRUE(test::readFile(dir.file("held/model.ply")) ==
              test::readFile(dir.file("streamed/model.ply")));
}

TEST(BlockRun, TheMergedRunEvaluatesEveryTestViewAsWellAsOneRun) {
  test::TempDir dir;
  std::string out;
  const std::string longer = " train " + kTinySceneCache + " --iterations 200";
  ASSERT_EQ(test::runCommand(kCli + longer + " --blocks 2 --out " + dir.file("blocks"), &out), 0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + longer + " --out " + dir.file("one"), &out), 0) << out;
  for (const char* run : {"blocks", "one"})
    ASSERT_EQ(test::runCommand(kCli + " eval " + dir.file(run), &out), 0) << out;
  const auto blocks = nlohmann::json::parse(test::readFile(dir.file("blocks/metrics.json")));
  const auto one = nlohmann::json::parse(test::readFile(dir.file("one/metrics.json")));
  int test_views = 0;
  for (const io::View& v : io::readSceneCache(kTinySceneCache).views) test_views += v.test;
  EXPECT_EQ(static_cast<int>(blocks["views"].size()), test_views);
  // Per view: the scores whose mean is the run's.
  ASSERT_EQ(blocks["per_view"].size(), blocks["views"].size());
  double psnr_sum = 0;
  for (const auto& v : blocks["per_view"]) {
    psnr_sum += v["psnr"].get<double>();
    EXPECT_GE(v["accuracy"].get<double>(), 0.0);
    EXPECT_LE(v["accuracy"].get<double>(), 1.0);
  }
  EXPECT_NEAR(psnr_sum / blocks["per_view"].size(), blocks["psnr"].get<double>(), 1e-9);
  // Measured (CPU, 2026-11-29): 6.67 dB / 67.3 % mIoU against one run's 6.85 dB / 74.8 %, and
  // 4.0 dB for either after 30 iterations (the tiny scene's 64 x 48 views are hard to fit).
  EXPECT_GT(blocks["psnr"].get<double>(), one["psnr"].get<double>() - 1.0);
  EXPECT_GT(blocks["miou"].get<double>(), 0.5);
}

TEST(BlockRun, TwoGlooRanksTrainTheBlocksAsOneProcessDoes) {
  if (!SADSPLAT_TEST_HAVE_GLOO) GTEST_SKIP() << "LibTorch without c10d Gloo";
  test::TempDir dir;
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + kBlockRun + " --out " + dir.file("one"), &out), 0) << out;
  ASSERT_EQ(test::runCommand(kCli + kBlockRun + " --nproc 2 --out " + dir.file("two"), &out), 0)
      << out;
  // Each rank trained one block on its own, with the same data and seed: the same model.
  const auto a = io::readGaussianPly(dir.file("one/model.ply"));
  const auto b = io::readGaussianPly(dir.file("two/model.ply"));
  ASSERT_EQ(a.size(), b.size());
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    d += std::abs(a[i].x - b[i].x) + std::abs(a[i].y - b[i].y) + std::abs(a[i].z - b[i].z);
  EXPECT_LT(d / a.size(), 1e-4);
}

TEST(BlockRun, MismatchedOptionsAreClearErrors) {
  test::TempDir dir;
  std::string out;
  EXPECT_EQ(test::runCommand(kCli + kBlockRun + " --batch-schedule --out " + dir.file("r"), &out),
            1);
  EXPECT_NE(out.find("--batch-schedule"), std::string::npos) << out;
  ASSERT_EQ(test::runCommand(kCli + kBlockRun + " --out " + dir.file("run"), &out), 0) << out;
  pipeline::TrainRunOptions o;
  o.scene = kTinySceneCache;
  o.out = dir.file("run");
  pipeline::BlockRunOptions b;
  b.partition.blocks = 2;
  b.partition.overlap = 0.5;  // not the partition the blocks were trained on
  try {
    pipeline::BlockRun(o, b).merge();
    FAIL() << "merged blocks of another partition";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("blocks.json"), std::string::npos) << e.what();
  }
}

// The largest block estimate of a partition into `blocks`.
std::int64_t largestEstimate(const io::Scene& scene, int blocks,
                             const gaussians::TrainConfig& config) {
  geo::BlockOptions options;
  options.blocks = blocks;
  std::int64_t largest = 0;
  for (const geo::Block& b : geo::partitionScene(scene, options, kTinySceneCache).blocks) {
    largest = std::max(largest, gaussians::estimateTrainingMemory(scene, b.views,
                                                                  b.points.size(), config)
                                    .total());
  }
  return largest;
}

// --blocks auto / --max-gpu-memory: the fewest blocks whose largest estimate fits.
TEST(BlockRun, AMemoryBudgetPicksTheFewestBlocksThatFit) {
  const io::Scene scene = io::readSceneCache(kTinySceneCache);
  gaussians::TrainConfig config;
  const std::int64_t whole = gaussians::estimateTrainingMemory(scene, config).total();
  const std::int64_t budget = largestEstimate(scene, 4, config);
  ASSERT_LT(budget, whole);
  geo::BlockOptions automatic;
  automatic.blocks = 0;
  const geo::BlockPartition p =
      pipeline::partitionForMemory(scene, automatic, config, budget, nullptr, kTinySceneCache);
  const int n = static_cast<int>(p.blocks.size());
  ASSERT_GE(n, 2);
  ASSERT_LE(n, 4);
  EXPECT_LE(largestEstimate(scene, n, config), budget);
  for (int fewer = 2; fewer < n; ++fewer) EXPECT_GT(largestEstimate(scene, fewer, config), budget);
  // What the whole scene needs: one block.
  EXPECT_EQ(pipeline::partitionForMemory(scene, automatic, config, whole, nullptr, kTinySceneCache)
                .blocks.size(),
            1u);
  // With a count (--blocks N --max-gpu-memory): at least that many.
  geo::BlockOptions at_least = automatic;
  at_least.blocks = n + 2;
  EXPECT_EQ(pipeline::partitionForMemory(scene, at_least, config, whole, nullptr, kTinySceneCache)
                .blocks.size(),
            static_cast<std::size_t>(n + 2));
  // Less than one step's render of a view: an error naming the option.
  try {
    pipeline::partitionForMemory(scene, automatic, config, 1000, nullptr, kTinySceneCache);
    FAIL() << "a budget of 1000 bytes was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--max-gpu-memory"), std::string::npos) << e.what();
  }
  // The command: the budget implies --blocks auto and says its estimates; auto needs a budget.
  test::TempDir dir;
  std::string out;
  const double gib = static_cast<double>(budget) / (1ll << 30);
  ASSERT_EQ(test::runCommand(kCli + kTrain + " --max-gpu-memory " +
                                 std::to_string(gib * 1.001) + " --out " + dir.file("run"),
                             &out),
            0)
      << out;
  EXPECT_NE(out.find("the whole scene in one run:"), std::string::npos) << out;
  EXPECT_NE(out.find("trained in " + std::to_string(n) + " blocks"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(kCli + kTrain + " --blocks auto --out " + dir.file("r2"), &out), 1);
  EXPECT_NE(out.find("--max-gpu-memory"), std::string::npos) << out;
  // info SCENE.cache says what training it would hold on a CUDA device, held and streamed.
  ASSERT_EQ(test::runCommand(kCli + " info " + kTinySceneCache, &out), 0) << out;
  config.device = gaussians::TrainDevice::kCuda;
  EXPECT_NE(out.find("views held:      " + gaussians::estimateTrainingMemory(scene, config)
                                               .describe()),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("--stream-views:"), std::string::npos) << out;
}

}  // namespace
}  // namespace sadsplat
