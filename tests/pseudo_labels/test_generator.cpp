#include <gtest/gtest.h>

#include <cmath>

#include "pseudo_labels/toy_scene.h"
#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/generator.h"
#include "sadsplat/pseudo_labels/point_visibility.h"
#include "sadsplat/pseudo_labels/quality_report.h"

namespace sp = sadsplat::pseudo_labels;
namespace io = sadsplat::io;

namespace {
sp::BuiltinOptions smallOptions() {
  sp::BuiltinOptions o;
  o.superpixels.region_size = 8;
  o.scale_region_size = false;
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

// What the annotated photos show, per class: a class no labelled training view shows gets 0
// (pseudo-labels warns of it by name); unlabelled and test views do not count.
TEST(AnnotatedPixels, CountTheClassesOfTheLabelledTrainingViewsOnly) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  std::vector<std::int64_t> expected(scene.classes.size(), 0);
  int labelled = 0;
  for (const io::View& v : scene.views) {
    if (!v.train || !v.labelled) continue;
    ++labelled;
    for (std::uint8_t c : v.labels.pixels) {
      if (c < expected.size()) ++expected[c];
    }
  }
  ASSERT_GT(labelled, 0);
  int views = -1;
  EXPECT_EQ(io::annotatedPixelsPerClass(scene, &views), expected);
  EXPECT_EQ(views, labelled);
  ASSERT_GT(expected[1], 0);
  // Relabel class 1 as ignored on every labelled view: it is then shown by none.
  for (io::View& v : scene.views) {
    if (!v.labelled) continue;
    for (std::uint8_t& c : v.labels.pixels) {
      if (c == 1) c = io::kIgnoreLabel;
    }
  }
  const std::vector<std::int64_t> after = io::annotatedPixelsPerClass(scene);
  EXPECT_EQ(after[1], 0);
  EXPECT_EQ(after[0], expected[0]);
  // A view that is labelled but not a training view does not count.
  for (io::View& v : scene.views) v.train = false;
  for (std::int64_t n : io::annotatedPixelsPerClass(scene, &views)) EXPECT_EQ(n, 0);
  EXPECT_EQ(views, 0);
}

TEST(PseudoLabelGenerator, BadOptionsAreErrorsNamingTheOption) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  auto scorer = sp::makeBuiltinScorer(smallOptions());
  auto message = [&](const sp::PseudoLabelOptions& o) -> std::string {
    try {
      sp::generatePseudoLabels(scene, *scorer, o);
    } catch (const sadsplat::Error& e) {
      return e.what();
    }
    return "no error";
  };
  sp::PseudoLabelOptions o;
  o.filter_k = std::nan("");
  EXPECT_NE(message(o).find("--filter-k"), std::string::npos) << message(o);
  o = {};
  o.min_view_agreement = 1.5;
  EXPECT_NE(message(o).find("--min-view-agreement"), std::string::npos) << message(o);
  o = {};
  o.min_class_precision = -0.1;
  EXPECT_NE(message(o).find("--min-class-precision"), std::string::npos) << message(o);
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
  EXPECT_EQ(q.worst_class, 1);  // class 0 at 100 %, class 1 at 50 %, class 2 labels nothing
  EXPECT_NE(q.toText().find("worst kept class: green 50.00 %"), std::string::npos) << q.toText();
  EXPECT_EQ(q.reliability[9].pixels, 2u);  // TOP1 0.95
  EXPECT_DOUBLE_EQ(q.reliability[9].accuracy, 1.0);
  EXPECT_EQ(q.reliability[8].pixels, 2u);  // TOP1 0.85
  EXPECT_DOUBLE_EQ(q.reliability[8].accuracy, 0.5);
  p.kept = {1, 0};
  const sp::PseudoLabelQuality q2 = sp::evaluatePseudoLabels(scene);
  EXPECT_DOUBLE_EQ(q2.precision, 1.0);
  EXPECT_DOUBLE_EQ(q2.coverage, 0.5);
  EXPECT_EQ(q2.worst_class, 0);  // the only class that labels anything
}

// Overlapping layers resolved by hand: 6 pixels in a row, two classes.
//   layer 0 targets: [0 0 1 2 -1 -1], TOP1 2 1 1, kept 1 0 0
//   layer 1 targets: [0 0 0 1  1 -1], TOP1 3 0,   kept 1 0
// Refined regions: pixels {0,1} -> layer-1 target 0 (kept, higher TOP1 than layer-0 target 0);
// {2} -> layer-1 target 0 (the only kept cover); {3} -> layer-0 target 2 (none kept: finest);
// {4} -> layer-1 target 1 (no layer-0 target there); pixel 5 -> no target.
TEST(ResolveLayers, HandMadeOverlapTakesTheBestKeptCover) {
  auto layer = [](std::vector<std::int32_t> region, int n, std::vector<float> scores) {
    sp::TargetLayer t;
    t.segmentation.width = 6;
    t.segmentation.height = 1;
    t.segmentation.num_regions = n;
    t.segmentation.region = std::move(region);
    t.scores = scores;
    t.feature_dim = 2;
    for (float& s : scores) s *= 10;  // features distinct from scores
    t.features = scores;
    return t;
  };
  const std::vector<sp::TargetLayer> layers = {
      layer({0, 0, 1, 2, -1, -1}, 3, {0.9f, 0.1f, 0.6f, 0.4f, 0.2f, 0.8f}),
      layer({0, 0, 0, 1, 1, -1}, 2, {0.3f, 0.7f, 0.5f, 0.5f})};
  std::vector<std::uint8_t> kept;
  const sp::TargetLayer out =
      sp::resolveLayers(layers, 2, {{2, 1, 1}, {3, 0}}, {{1, 0, 0}, {1, 0}}, kept);
  ASSERT_EQ(out.segmentation.num_regions, 4);
  const std::vector<std::int32_t>& r = out.segmentation.region;
  EXPECT_EQ(r[0], r[1]);
  EXPECT_EQ(r[5], -1);
  const std::vector<std::vector<float>> expected_scores = {
      {0.3f, 0.7f}, {0.3f, 0.7f}, {0.3f, 0.7f}, {0.2f, 0.8f}, {0.5f, 0.5f}};
  const std::vector<int> expected_kept = {1, 1, 1, 0, 0};
  for (int i = 0; i < 5; ++i) {
    ASSERT_GE(r[i], 0) << i;
    EXPECT_FLOAT_EQ(out.scores[2 * r[i]], expected_scores[i][0]) << i;
    EXPECT_FLOAT_EQ(out.scores[2 * r[i] + 1], expected_scores[i][1]) << i;
    EXPECT_FLOAT_EQ(out.features[2 * r[i]], 10 * expected_scores[i][0]) << i;
    EXPECT_EQ(kept[r[i]], expected_kept[i]) << i;
  }
  for (int i = 2; i < 5; ++i) EXPECT_NE(r[i], r[i - 1]) << i;

  sp::TargetLayer wrong = layers[1];
  wrong.segmentation.width = 3;
  wrong.segmentation.height = 2;
  EXPECT_THROW(
      sp::resolveLayers({layers[0], wrong}, 2, {{2, 1, 1}, {3, 0}}, {{1, 0, 0}, {1, 0}}, kept),
      sadsplat::Error);
  EXPECT_THROW(sp::resolveLayers({}, 2, {}, {}, kept), sadsplat::Error);
}

TEST(PseudoLabelGenerator, MultiscaleTargetsRefineTheFinestLayerAndStayRight) {
  io::Scene single = sadsplat::test::toyPseudoLabelScene();
  io::Scene multi = single;
  sp::BuiltinOptions o = smallOptions();
  const sp::PseudoLabelSummary s1 = sp::generatePseudoLabels(single, *sp::makeBuiltinScorer(o));
  o.targets = sp::MaskGenerator::kSlicMultiscale;
  o.multiscale = {1, 2};
  const sp::PseudoLabelSummary s2 = sp::generatePseudoLabels(multi, *sp::makeBuiltinScorer(o));
  // Every target of both layers is a sample of the filter.
  EXPECT_GT(s2.targets, s1.targets);
  for (std::size_t k = 0; k < multi.views.size(); ++k) {
    const io::View& v = multi.views[k];
    if (!v.train) continue;
    EXPECT_NO_THROW(v.pseudo.validate("test", v.rgb.pixels.size() / 3));
    // The stored partition refines the finest layer (the single-scale SLIC targets).
    const std::vector<std::int32_t>& fine = single.views[k].pseudo.region;
    std::vector<int> parent(v.pseudo.num_targets, -2);
    for (std::size_t i = 0; i < fine.size(); ++i) {
      const int r = v.pseudo.region[i];
      ASSERT_EQ(r < 0, fine[i] < 0) << i;
      if (r < 0) continue;
      if (parent[r] == -2) parent[r] = fine[i];
      EXPECT_EQ(parent[r], fine[i]) << "stored region " << r << " spans two finest targets";
    }
  }
  const sp::PseudoLabelQuality q = sp::evaluatePseudoLabels(multi);
  EXPECT_GT(q.coverage, 0.05);
  EXPECT_GE(q.precision, 0.97);

  o.multiscale = {2, 1};
  EXPECT_THROW(sp::generatePseudoLabels(multi, *sp::makeBuiltinScorer(o)), sadsplat::Error);
}

TEST(PseudoLabelGenerator, PerClassFilterUsesTheStatisticsOfEachClass) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene();
  sp::PseudoLabelOptions options;
  options.per_class = false;  // the paper's filter
  const sp::PseudoLabelSummary pooled =
      sp::generatePseudoLabels(scene, *sp::makeBuiltinScorer(smallOptions()), options);
  EXPECT_TRUE(pooled.class_statistics.empty());
  options.per_class = true;
  const sp::PseudoLabelSummary s =
      sp::generatePseudoLabels(scene, *sp::makeBuiltinScorer(smallOptions()), options);
  ASSERT_EQ(s.class_statistics.size(), 3u);
  EXPECT_EQ(s.targets, pooled.targets);
  std::size_t per_class_targets = 0;
  for (const sp::TargetStatistics& c : s.class_statistics) per_class_targets += c.count;
  EXPECT_EQ(per_class_targets, s.targets);  // every toy class has enough targets of its own
  std::vector<int> kept_pixels(3, 0);
  for (const io::View& v : scene.views) {
    if (!v.train) continue;
    for (std::int16_t l : v.pseudo.labelMap())
      if (l >= 0) ++kept_pixels[l];
  }
  for (int c = 0; c < 3; ++c) EXPECT_GT(kept_pixels[c], 0) << "class " << c;
  EXPECT_GE(sp::evaluatePseudoLabels(scene).precision, 0.97);
}

namespace {
// Five one-column targets per 5x2 view: columns 0 and 1 confident (class 0, class 2), the others
// nearly uniform, so that the filter keeps exactly columns 0 and 1 (2 of 5 above mean + std).
class ColumnScorer : public sp::TargetScorer {
 public:
  std::string name() const override { return "columns"; }
  std::vector<sp::ViewTargets> score(const io::Scene& scene, const std::vector<int>& views,
                                     const sp::ProgressFn&) override {
    std::vector<sp::ViewTargets> out;
    for (std::size_t k = 0; k < views.size(); ++k) {
      sp::TargetLayer t;
      t.segmentation.width = 5;
      t.segmentation.height = 2;
      t.segmentation.num_regions = 5;
      for (int i = 0; i < 10; ++i) t.segmentation.region.push_back(i % 5);
      t.scores = {0.96f, 0.02f, 0.02f, 0.02f, 0.02f, 0.96f, 0.34f, 0.33f,
                  0.33f, 0.33f, 0.34f, 0.33f, 0.33f, 0.33f, 0.34f};
      t.feature_dim = 3;
      t.features = t.scores;
      out.push_back({{t}});
    }
    (void)scene;
    return out;
  }
};

io::Scene columnScene() {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene(3, 5, 2);
  // View 0 (labelled): column 0 is class 0 (the scorer is right), column 1 class 1 (the scorer
  // says 2: wrong), the rest class 0.
  for (int i = 0; i < 10; ++i) scene.views[0].labels.pixels[i] = i % 5 == 1 ? 1 : 0;
  return scene;
}
}  // namespace

TEST(PseudoLabelGenerator, ClassCheckOnTheLabelledViewsRemovesAnUnreliableClass) {
  io::Scene scene = columnScene();
  ColumnScorer scorer;
  sp::PseudoLabelOptions options;
  options.per_class = false;  // the paper's filter, by hand in ColumnScorer's comment
  options.filter_k = 1;
  sp::PseudoLabelSummary s = sp::generatePseudoLabels(scene, scorer, options);
  ASSERT_EQ(s.kept_targets, 4u);  // columns 0 and 1 of the two training views
  EXPECT_EQ(s.kept_regions, 4u);
  ASSERT_EQ(s.check_pixels.size(), 3u);
  EXPECT_EQ(s.check_pixels[0], 2u);
  EXPECT_EQ(s.check_correct[0], 2u);
  EXPECT_EQ(s.check_pixels[2], 2u);
  EXPECT_EQ(s.check_correct[2], 0u);
  EXPECT_EQ(s.class_rejected, std::vector<bool>(3, false));  // off by default

  options.min_class_precision = 0.9;
  options.min_check_pixels = 2;
  s = sp::generatePseudoLabels(scene, scorer, options);
  EXPECT_EQ(s.class_rejected, (std::vector<bool>{false, false, true}));
  EXPECT_EQ(s.kept_targets, 4u);  // passed the filter
  EXPECT_EQ(s.kept_regions, 2u);  // left after the check
  const std::vector<std::int16_t> unlabelled = scene.views[1].pseudo.labelMap();
  EXPECT_EQ(unlabelled[0], 0);   // class 0 kept
  EXPECT_EQ(unlabelled[1], -1);  // class 2 removed on the unlabelled view too

  // Too little evidence: nothing is removed.
  options.min_check_pixels = 3;
  s = sp::generatePseudoLabels(scene, scorer, options);
  EXPECT_EQ(s.kept_regions, 4u);
}

// Camera at the origin looking along +z (toy scene cameras, moved), 8x8 pixels, f = 8: a point
// (x, y, z) lands at pixel (8x/z + 4, 8y/z + 4).
TEST(PointVisibility, NearerPointsOfACellHideFartherOnes) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene(2, 8, 8);
  io::View& v = scene.views[0];
  v.camera.fx = v.camera.fy = 8;
  v.camera.cx = v.camera.cy = 4;
  v.camera.tvec = {0, 0, 0};
  auto point = [](float x, float y, float z) {
    io::ScenePoint p;
    p.xyz = {x, y, z};
    return p;
  };
  scene.points = {point(0, 0, 4),          // pixel (4, 4), cell (1, 1)
                  point(0.25f, 0, 8),      // pixel (4, 4): same cell, twice as far: hidden
                  point(0.25f, 0, 4.05f),  // pixel (4.5 -> 4, 4): within 2 %: seen
                  point(-2.5f, -2.5f, 5),  // pixel (0, 0), cell (0, 0)
                  point(3, 0, 4),          // pixel (10, 4): outside
                  point(0, 0, -4)};        // behind the camera
  const std::vector<sp::PointHit> hits = sp::visiblePoints(scene, v, 4);
  ASSERT_EQ(hits.size(), 3u);
  EXPECT_EQ(hits[0].point, 0u);
  EXPECT_EQ(hits[0].pixel, 4u * 8 + 4);
  EXPECT_EQ(hits[1].point, 2u);
  EXPECT_EQ(hits[2].point, 3u);
  EXPECT_EQ(hits[2].pixel, 0u);
  // With 1-pixel cells, points 1 and 2 fall in pixel (4, 4) with point 0: still hidden / seen.
  EXPECT_EQ(sp::visiblePoints(scene, v, 1).size(), 3u);
}

// Three views with the same camera see the same 16 points; each view has two regions (left and
// right half). The left half is class 0 in view 0 but class 2 in views 1 and 2: view 0's left
// label is outvoted 0 : 16, views 1 and 2 agree with each other 8 : 16 (one of two other views).
TEST(ViewAgreementCheck, OutvotedRegionsAreUnkept) {
  io::Scene scene = sadsplat::test::toyPseudoLabelScene(4, 8, 8);
  std::vector<int> views = {0, 1, 2};
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      io::ScenePoint p;
      // Toy cameras: f = 8, centre (4, 4), 10 units in front: pixel (2x + 0.5, 2y + 0.5).
      p.xyz = {(2 * x + 0.5f - 4) * 10 / 8, (2 * y + 0.5f - 4) * 10 / 8, 0};
      scene.points.push_back(p);
    }
  }
  for (int i : views) {
    io::ViewPseudoLabels& p = scene.views[i].pseudo;
    p.num_classes = 3;
    p.num_targets = 2;
    p.region.resize(64);
    for (int px = 0; px < 64; ++px) p.region[px] = px % 8 < 4 ? 0 : 1;
    const int left = i == 0 ? 0 : 2;
    p.scores.assign(6, 0.05f);
    p.scores[left] = 0.9f;
    p.scores[3 + 1] = 0.9f;
    p.kept = {1, 1};
  }
  ASSERT_EQ(sp::visiblePoints(scene, scene.views[0]).size(), 16u);
  io::Scene strict = scene;
  std::vector<std::size_t> removed = sp::applyViewAgreementCheck(scene, views, 0.5, 16);
  EXPECT_EQ(removed, (std::vector<std::size_t>{1, 0, 0}));
  EXPECT_EQ(scene.views[0].pseudo.kept, (std::vector<std::uint8_t>{0, 1}));
  EXPECT_EQ(scene.views[1].pseudo.kept, (std::vector<std::uint8_t>{1, 1}));  // 8 of 16 = 0.5
  // A stricter share also unkeeps views 1 and 2's left halves; the right halves agree 16 of 16.
  removed = sp::applyViewAgreementCheck(strict, views, 0.6, 16);
  EXPECT_EQ(removed, (std::vector<std::size_t>{1, 0, 2}));
  EXPECT_EQ(strict.views[2].pseudo.kept, (std::vector<std::uint8_t>{0, 1}));
  // Fewer votes than asked for (8 points x 2 other views = 16 per region): nothing changes.
  io::Scene few = strict;
  for (int i : views) few.views[i].pseudo.kept = {1, 1};
  EXPECT_EQ(sp::applyViewAgreementCheck(few, views, 0.6, 17), std::vector<std::size_t>(3, 0));
  // No sparse points, no evidence: nothing is unkept.
  few.points.clear();
  EXPECT_EQ(sp::applyViewAgreementCheck(few, views, 0.6, 1), std::vector<std::size_t>(3, 0));
  EXPECT_EQ(few.views[0].pseudo.kept, (std::vector<std::uint8_t>{1, 1}));
}

TEST(BuiltinOptions, RegionSizeScalesWithTheViewArea) {
  EXPECT_EQ(sp::scaledRegionSize(16, 800, 450), 16);
  EXPECT_EQ(sp::scaledRegionSize(16, 1600, 900), 32);
  EXPECT_EQ(sp::scaledRegionSize(16, 320, 180), 6);   // 6.4
  EXPECT_EQ(sp::scaledRegionSize(16, 64, 48), 4);     // 1.5, raised to the minimum
  EXPECT_EQ(sp::scaledRegionSize(24, 900, 400), 24);  // same area as 800x450
}
