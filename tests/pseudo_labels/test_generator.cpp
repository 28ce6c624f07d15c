#include <gtest/gtest.h>

#include "pseudo_labels/toy_scene.h"
#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/generator.h"
#include "sadsplat/pseudo_labels/quality_report.h"

namespace sp = sadsplat::pseudo_labels;
namespace io = sadsplat::io;

namespace {
sp::BuiltinOptions smallOptions() {
  sp::BuiltinOptions o;
  o.superpixels.region_size = 8;
  o.classifier.steps = 200;
  return o;
}
}  // namespace

TEST(PseudoLabelGenerator, BuiltinFillsEveryTrainingViewWithValidMaps) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  auto scorer = sp::makeBuiltinScorer(smallOptions());
  const sp::PseudoLabelSummary s = sp::generatePseudoLabels(scene, *scorer);
  EXPECT_EQ(s.backend, "builtin");
  EXPECT_EQ(s.views, 4);
  EXPECT_GT(s.kept_targets, 0u);
  EXPECT_LT(s.kept_targets, s.targets);
  for (const io::View& v : scene.views) {
    if (!v.train) {
      EXPECT_TRUE(v.pseudo.empty());
      continue;
    }
    const io::ViewPseudoLabels& p = v.pseudo;
    ASSERT_FALSE(p.empty());
    EXPECT_NO_THROW(p.validate("test", v.rgb.pixels.size() / 3));
    for (int t = 0; t < p.num_targets; ++t) {
      double sum = 0;
      for (int c = 0; c < 3; ++c) sum += p.scores[t * 3 + c];
      EXPECT_NEAR(sum, 1.0, 1e-5);
    }
    const std::vector<float> conf = p.confidenceMap();
    const std::vector<float> best = p.maxScoreMap();
    ASSERT_EQ(conf.size(), best.size() * 3);
    for (std::size_t i = 0; i < best.size(); ++i) {
      EXPECT_FLOAT_EQ(best[i], std::max({conf[3 * i], conf[3 * i + 1], conf[3 * i + 2]}));
      EXPECT_GE(conf[3 * i], 0.0f);
      EXPECT_LE(conf[3 * i], 1.0f);
    }
  }
  // The toy classes are separable by colour: kept pseudo-labels are right.
  const sp::PseudoLabelQuality q = sp::evaluatePseudoLabels(scene);
  EXPECT_EQ(q.views, 3);
  EXPECT_GT(q.coverage, 0.05);
  EXPECT_GE(q.precision, 0.97) << "argmax accuracy " << q.argmax_accuracy << ", coverage "
                               << q.coverage;
}

TEST(PseudoLabelGenerator, GroundTruthOverridesPseudoLabels) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  auto scorer = sp::makeBuiltinScorer(smallOptions());
  sp::generatePseudoLabels(scene, *scorer);
  io::View& labelled = scene.views[0];
  ASSERT_TRUE(labelled.labelled);
  // Make every target of the labelled view a kept, wrong pseudo-label.
  for (int t = 0; t < labelled.pseudo.num_targets; ++t) {
    labelled.pseudo.kept[t] = 1;
    for (int c = 0; c < 3; ++c) labelled.pseudo.scores[t * 3 + c] = c == 0 ? 1.0f : 0.0f;
  }
  labelled.labels.pixels[5] = io::kIgnoreLabel;
  const std::vector<std::int16_t> sup = io::supervisionLabels(labelled);
  for (std::size_t i = 0; i < sup.size(); ++i) {
    const int gt = labelled.labels.pixels[i];
    EXPECT_EQ(sup[i], gt == io::kIgnoreLabel ? -1 : gt) << i;
  }
  // An unlabelled training view is supervised by its kept pseudo-labels only, or not at all.
  const io::View& other = scene.views[1];
  EXPECT_EQ(io::supervisionLabels(other), other.pseudo.labelMap());
  for (std::int16_t l : io::supervisionLabels(other, false)) EXPECT_EQ(l, -1);
}

TEST(PseudoLabelGenerator, WithoutLabelledViewsTheBuiltinBackendStops) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  for (io::View& v : scene.views) v.labelled = false;
  auto scorer = sp::makeBuiltinScorer(smallOptions());
  try {
    sp::generatePseudoLabels(scene, *scorer);
    FAIL() << "expected an error";
  } catch (const sadsplat::Error& e) {
    EXPECT_NE(std::string(e.what()).find("labelled"), std::string::npos) << e.what();
  }
}

// Quality figures on a hand-made case: one unlabelled training view of 4 pixels, 2 targets.
TEST(PseudoLabelQuality, HandComputedPrecisionCoverageAndReliability) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene(2, 2, 2);
  io::View& v = scene.views[0];
  v.labelled = false;
  v.labels.pixels = {0, 0, 1, 2};
  io::ViewPseudoLabels& p = v.pseudo;
  p.region = {0, 0, 1, 1};
  p.num_targets = 2;
  p.num_classes = 3;
  p.scores = {0.95f, 0.05f, 0.0f,    // target 0: class 0, kept, both pixels right
              0.10f, 0.85f, 0.05f};  // target 1: class 1, kept: right on pixel 2, wrong on 3
  p.kept = {1, 1};
  const sp::PseudoLabelQuality q = sp::evaluatePseudoLabels(scene);
  EXPECT_EQ(q.gt_pixels, 4u);
  EXPECT_EQ(q.kept_pixels, 4u);
  EXPECT_DOUBLE_EQ(q.precision, 0.75);
  EXPECT_DOUBLE_EQ(q.coverage, 1.0);
  EXPECT_DOUBLE_EQ(q.classes[1].precision, 0.5);
  EXPECT_DOUBLE_EQ(q.classes[2].coverage, 1.0);  // its pixel was kept (with a wrong label)
  EXPECT_EQ(q.reliability[9].pixels, 2u);        // TOP1 0.95
  EXPECT_DOUBLE_EQ(q.reliability[9].accuracy, 1.0);
  EXPECT_EQ(q.reliability[8].pixels, 2u);  // TOP1 0.85
  EXPECT_DOUBLE_EQ(q.reliability[8].accuracy, 0.5);
  p.kept = {1, 0};
  const sp::PseudoLabelQuality q2 = sp::evaluatePseudoLabels(scene);
  EXPECT_DOUBLE_EQ(q2.precision, 1.0);
  EXPECT_DOUBLE_EQ(q2.coverage, 0.5);
}
