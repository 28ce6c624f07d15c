#include <gtest/gtest.h>

#include <cmath>

#include "pseudo_labels/toy_scene.h"
#include "sadsplat/common/error.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/pseudo_labels/torchscript_scorer.h"
#include "test_support/test_support.h"

namespace sp = sadsplat::pseudo_labels;
namespace io = sadsplat::io;

namespace {
const std::string kSam = std::string(SADSPLAT_TEST_DATA_DIR) + "/models/tiny_sam.pt";
const std::string kClip = std::string(SADSPLAT_TEST_DATA_DIR) + "/models/tiny_clip.pt";

sp::MaskGenerationOptions tinyOptions() {
  sp::MaskGenerationOptions o;
  o.points_per_side = 6;
  o.points_per_batch = 16;
  o.pred_iou_threshold = 0.0;  // the tiny model's IoU head is random
  o.stability_threshold = 0.5;
  return o;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const sadsplat::Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(TorchScriptScorer, RunsEndToEndOnTinyModels) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  auto scorer = sp::makeTorchScriptScorer(kSam, kClip, tinyOptions());
  EXPECT_EQ(scorer->name(), "torchscript");
  const sp::PseudoLabelSummary s = sp::generatePseudoLabels(scene, *scorer);
  EXPECT_EQ(s.views, 4);
  EXPECT_GT(s.targets, 4u);
  for (const io::View& v : scene.views) {
    if (!v.train) continue;
    const io::ViewPseudoLabels& p = v.pseudo;
    ASSERT_GT(p.num_targets, 0) << v.name;
    EXPECT_EQ(p.feature_dim, 16);
    EXPECT_NO_THROW(p.validate("test", v.rgb.pixels.size() / 3));
    for (int t = 0; t < p.num_targets; ++t) {
      double sum = 0, norm = 0;
      for (int c = 0; c < 3; ++c) sum += p.scores[t * 3 + c];
      for (int k = 0; k < 16; ++k) norm += p.features[t * 16 + k] * p.features[t * 16 + k];
      EXPECT_NEAR(sum, 1.0, 1e-5);
      EXPECT_NEAR(norm, 1.0, 1e-4);  // unit image embeddings
    }
    // The tiny SAM's masks follow colour, so no target straddles two toy blocks of different
    // colour by much: each target's majority class covers >= 80 % of it.
    std::vector<std::array<int, 3>> hist(p.num_targets, {0, 0, 0});
    for (std::size_t i = 0; i < p.region.size(); ++i) {
      if (p.region[i] >= 0) hist[p.region[i]][v.labels.pixels[i]]++;
    }
    for (const auto& h : hist) {
      const int total = h[0] + h[1] + h[2];
      EXPECT_GE(*std::max_element(h.begin(), h.end()), 0.8 * total);
    }
  }
}

TEST(TorchScriptScorer, CliRunsTheBackendOnACache) {
  sadsplat::test::TempDir dir;
  io::writeSceneCache(dir.file("toy.cache"), sadsplat::test::toyPseudoLabelScene());
  std::string output;
  const int rc =
      sadsplat::test::runCommand(std::string(SADSPLAT_CLI) + " pseudo-labels " +
                                     dir.file("toy.cache") + " --backend torchscript --sam " +
                                     kSam + " --clip " + kClip + " --report " + dir.file("report"),
                                 &output);
  // SAM's default thresholds (pred IoU 0.88) reject most of the tiny model's masks; what passes
  // still makes a valid cache and report.
  ASSERT_EQ(rc, 0) << output;
  const io::Scene back = io::readSceneCache(dir.file("toy.cache"));
  EXPECT_FALSE(back.views[0].pseudo.empty());
  EXPECT_EQ(back.views[0].pseudo.backend, "torchscript");
  EXPECT_NE(sadsplat::test::readFile(dir.file("report/report.json")).find("precision"),
            std::string::npos);
}

TEST(TorchScriptScorer, BadModelFilesGiveClearErrors) {
  sadsplat::test::TempDir dir;
  EXPECT_NE(errorOf([&] { sp::makeTorchScriptScorer(dir.file("nope.pt"), kClip); }).find("nope.pt"),
            std::string::npos);
  sadsplat::test::writeFile(dir.file("text.pt"), "not a model");
  const std::string garbage =
      errorOf([&] { sp::makeTorchScriptScorer(dir.file("text.pt"), kClip); });
  EXPECT_NE(garbage.find("text.pt"), std::string::npos) << garbage;
  EXPECT_NE(garbage.find("TorchScript"), std::string::npos) << garbage;
  // The SAM file where the CLIP file belongs: its methods are missing.
  const std::string swapped = errorOf([&] { sp::makeTorchScriptScorer(kSam, kSam); });
  EXPECT_NE(swapped.find("encode_image"), std::string::npos) << swapped;
}

TEST(TorchScriptScorer, PromptsMustMatchTheScene) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  scene.classes[1].prompt = "grass";
  auto scorer = sp::makeTorchScriptScorer(kSam, kClip, tinyOptions());
  const std::string e = errorOf([&] { sp::generatePseudoLabels(scene, *scorer); });
  EXPECT_NE(e.find("class_prompts"), std::string::npos) << e;
  EXPECT_NE(e.find("red, grass, blue"), std::string::npos) << e;
}

TEST(TorchScriptScorer, BoxNmsKeepsTheBestOfOverlappingBoxes) {
  // Boxes 0 (10x10) and 1 (9x9, inside 0) overlap with IoU 81/100; box 2 is apart.
  const std::vector<std::array<float, 4>> boxes = {{0, 0, 9, 9}, {1, 1, 9, 9}, {20, 20, 29, 29}};
  EXPECT_EQ(sp::boxNms(boxes, {0.5f, 0.9f, 0.7f}, 0.8), (std::vector<int>{1, 2}));
  EXPECT_EQ(sp::boxNms(boxes, {0.5f, 0.9f, 0.7f}, 0.82), (std::vector<int>{1, 2, 0}));
}
