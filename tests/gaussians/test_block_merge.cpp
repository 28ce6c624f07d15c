// One model from blocks (gaussians/block_merge.h): the kept rows of every per-Gaussian tensor in
// block order, global state from the reference block, and the decoders made one so that every
// Gaussian decodes to the class scores its own block's decoder gave it.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/block_merge.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/scene_cache.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

constexpr int kClasses = 3;
constexpr int kFeatures = 8;

gaussians::BlockCheckpoint block(std::int64_t n, std::uint64_t seed, const std::string& name) {
  at::manual_seed(seed);
  gaussians::BlockCheckpoint b;
  b.origin = name;
  b.archive.tensors["means"] = at::randn({n, 3});
  b.archive.tensors["features"] = at::randn({n, kFeatures});
  b.archive.tensors["features.m"] = at::randn({n, kFeatures});
  b.archive.tensors["features.v"] = at::rand({n, kFeatures});
  b.archive.tensors["decoder_w"] = at::randn({kClasses, kFeatures});
  b.archive.tensors["decoder_b"] = at::randn({kClasses});
  b.archive.tensors["drop_guard"] = at::full({4}, static_cast<std::int64_t>(seed), at::kLong);
  b.archive.numbers["iteration"] = 100 + static_cast<double>(seed);
  b.keep = at::rand({n}) > 0.4;
  return b;
}

const std::vector<std::string> kRows = {"means", "features", "features.m", "features.v"};

TEST(BlockMerge, KeepsEachBlocksRowsInOrderAndTheReferencesGlobalState) {
  const std::vector<gaussians::BlockCheckpoint> blocks = {block(50, 1, "a"), block(70, 2, "b"),
                                                          block(30, 3, "c")};
  const gaussians::TensorArchive m = gaussians::mergeBlockCheckpoints(blocks, kRows, 1);
  std::int64_t kept = 0;
  for (const auto& b : blocks) kept += b.keep.sum().item<std::int64_t>();
  ASSERT_EQ(m.tensors.at("means").size(0), kept);
  std::int64_t row = 0;
  for (const auto& b : blocks) {
    const at::Tensor rows = b.archive.tensors.at("means").index({b.keep});
    EXPECT_TRUE(at::equal(m.tensors.at("means").narrow(0, row, rows.size(0)), rows));
    row += rows.size(0);
  }
  EXPECT_TRUE(at::equal(m.tensors.at("decoder_w"), blocks[1].archive.tensors.at("decoder_w")));
  EXPECT_TRUE(at::equal(m.tensors.at("drop_guard"), blocks[1].archive.tensors.at("drop_guard")));
  EXPECT_EQ(m.numbers.at("iteration"), 102);
}

TEST(BlockMerge, EveryGaussianDecodesToItsOwnBlocksScoresThroughTheOneDecoder) {
  const std::vector<gaussians::BlockCheckpoint> blocks = {block(40, 4, "a"), block(60, 5, "b")};
  const gaussians::TensorArchive m = gaussians::mergeBlockCheckpoints(blocks, kRows, 0);
  const at::Tensor w0 = m.tensors.at("decoder_w"), b0 = m.tensors.at("decoder_b");
  const at::Tensor merged_scores = at::linear(m.tensors.at("features"), w0, b0);
  std::int64_t row = 0;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const auto& t = blocks[k].archive.tensors;
    const at::Tensor own = at::linear(t.at("features"), t.at("decoder_w"), t.at("decoder_b"))
                               .index({blocks[k].keep});
    const at::Tensor got = merged_scores.narrow(0, row, own.size(0));
    EXPECT_LT((got - own).abs().max().item<double>(), 1e-4) << "block " << k;
    EXPECT_TRUE(at::equal(got.argmax(1), own.argmax(1))) << "the labels stay";
    const at::Tensor moments = m.tensors.at("features.m").narrow(0, row, own.size(0));
    if (k == 0) {
      EXPECT_TRUE(at::equal(moments, t.at("features.m").index({blocks[k].keep})));
      EXPECT_TRUE(at::equal(m.tensors.at("features").narrow(0, row, own.size(0)),
                            t.at("features").index({blocks[k].keep})))
          << "the reference block's features are its own";
    } else {
      EXPECT_EQ(moments.abs().sum().item<double>(), 0) << "moved features restart their moments";
    }
    row += own.size(0);
  }
}

TEST(BlockMerge, DisagreeingBlocksAreClearErrors) {
  std::vector<gaussians::BlockCheckpoint> blocks = {block(10, 6, "a.bin"), block(10, 7, "b.bin")};
  blocks[1].archive.tensors["decoder_w"] = at::zeros({kClasses + 1, kFeatures});
  try {
    gaussians::mergeBlockCheckpoints(blocks, kRows, 0);
    FAIL() << "decoder shapes differ";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("b.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("decoder_w"), std::string::npos) << e.what();
  }
  blocks[1] = block(10, 7, "b.bin");
  blocks[1].keep = at::ones({11}, at::kBool);
  EXPECT_THROW(gaussians::mergeBlockCheckpoints(blocks, kRows, 0), Error);
  EXPECT_THROW(gaussians::mergeBlockCheckpoints({}, kRows, 0), Error);
  EXPECT_THROW(gaussians::mergeBlockCheckpoints(blocks, kRows, 2), Error);
}

TEST(BlockMerge, TheTrainersRowTensorsAreItsPerGaussianState) {
  const io::Scene scene = io::readSceneCache(test::kTinySceneCache);
  gaussians::TrainConfig config;
  gaussians::Trainer trainer(scene, config);
  const std::vector<std::string> rows = trainer.checkpointRowTensors();
  const gaussians::TensorArchive a = trainer.checkpointSnapshot();
  const std::int64_t n = trainer.numGaussians();
  for (const auto& [name, t] : a.tensors) {
    const bool listed = std::find(rows.begin(), rows.end(), name) != rows.end();
    if (listed) EXPECT_EQ(t.size(0), n) << name;
  }
  for (const char* name : {"means", "features", "features.m", "grad_accum", "confidence"})
    EXPECT_NE(std::find(rows.begin(), rows.end(), name), rows.end()) << name;
  for (const char* name : {"decoder_w", "decoder_b", "drop_guard"})
    EXPECT_EQ(std::find(rows.begin(), rows.end(), name), rows.end()) << name;
  // Every tensor with one row per Gaussian is listed (none would be merged as global).
  std::size_t per_gaussian = 0;
  for (const auto& [name, t] : a.tensors) per_gaussian += t.dim() > 0 && t.size(0) == n;
  EXPECT_EQ(per_gaussian, rows.size());
}

}  // namespace
}  // namespace sadsplat
