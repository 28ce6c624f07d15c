// The trainer on the tiny fixture scene: loss falls, semantic masking, densification keeps the
// state consistent, resume is exact, configuration JSON.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/contribution.h"
#include "sadsplat/gaussians/densification.h"
#include "sadsplat/gaussians/schedule.h"
#include "sadsplat/gaussians/sparse_depth_loss.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/gaussians/view_coverage.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/scene_cache.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using gaussians::TensorArchive;
using gaussians::TrainConfig;
using gaussians::Trainer;

// The fixture scene as a cache (data/tiny_scene.cache, checked against a fresh import in
// test_io), so these tests need no OpenCV and run on the GPU build too.
const std::string kSceneCache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";

class TrainerTest : public ::testing::Test {
 protected:
  void SetUp() override { scene_ = io::readSceneCache(kSceneCache); }
  // The fixture scene's extent, as the trainer computes it (from every view's camera).
  double sceneExtent() const {
    std::vector<gaussians::RasterCamera> cameras;
    for (const io::View& v : scene_.views) {
      cameras.push_back(gaussians::RasterCamera::fromPinhole(v.camera));
    }
    return gaussians::sceneExtent(cameras);
  }
  static TrainConfig small(int iterations, const std::string& device = "cpu") {
    TrainConfig c;
    c.iterations = iterations;
    c.feature_dim = 8;
    c.densify_from = 100000;  // off unless a test turns it on
    c.checkpoint_interval = 0;
    c.device = gaussians::parseChoice<gaussians::TrainDevice>(device, "test", "device");
    return c;
  }
  io::Scene scene_;
};

// The tests that run on every device of the build: CPU, and CUDA where there is one.
class TrainerOnDevice : public TrainerTest, public ::testing::WithParamInterface<std::string> {
 protected:
  void SetUp() override {
    if (GetParam() == "cuda" && !at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
    TrainerTest::SetUp();
  }
  TrainConfig small(int iterations) const { return TrainerTest::small(iterations, GetParam()); }
};
INSTANTIATE_TEST_SUITE_P(Devices, TrainerOnDevice, ::testing::Values("cpu", "cuda"));

// Trains 240 steps; the mean RGB loss of the first and of the last 30.
std::pair<double, double> firstAndLastRgbLoss(Trainer& trainer) {
  double first = 0, last = 0;
  for (int i = 0; i < 240; ++i) {
    const auto stats = trainer.step();
    if (i < 30) first += stats.rgb_loss / 30;
    if (i >= 210) last += stats.rgb_loss / 30;
  }
  return {first, last};
}

TEST_P(TrainerOnDevice, RgbLossFallsOnTheTinyScene) {
  Trainer trainer(scene_, small(240));
  const auto [first, last] = firstAndLastRgbLoss(trainer);
  EXPECT_LT(last, 0.7 * first) << "first " << first << " last " << last;
  EXPECT_EQ(trainer.iteration(), 240);
}

// A scene without sparse points (transforms.json without a point cloud) starts from random points
// in the cameras' common view and still learns the views.
TEST_P(TrainerOnDevice, ASceneWithoutPointsTrainsFromRandomPoints) {
  io::Scene scene = scene_;
  scene.points.clear();
  TrainConfig config = small(240);
  config.init = gaussians::InitMode::kPoints;
  EXPECT_THROW(Trainer(scene, config), Error);
  config.init = gaussians::InitMode::kAuto;
  config.init_random_count = 3000;
  Trainer trainer(scene, config);
  EXPECT_EQ(trainer.numGaussians(), 3000);
  const auto [first, last] = firstAndLastRgbLoss(trainer);
  EXPECT_LT(last, 0.7 * first) << "first " << first << " last " << last;
}

// After densification, Gaussians larger than large_split_scale x the extent are split in two
// every densify_interval (not pruned), up to large_split_last iterations before the end.
TEST_P(TrainerOnDevice, LargeGaussiansAreSplitAfterDensificationWhenAsked) {
  TrainConfig config = small(250);
  config.densify_until = 100;  // densification itself stays off (densify_from is past the end)
  config.densify_interval = 100;
  config.large_split_last = 0;
  config.scale_limit = 0;  // the default late scale limit would split too (at 215 of 250)
  Trainer plain(scene_, config);
  const std::int64_t start = plain.numGaussians();
  for (int i = 0; i < 250; ++i) plain.step(false);
  EXPECT_EQ(plain.numGaussians(), start) << "off by default";

  config.large_split_scale = 1e-6;  // every Gaussian is "large": each round doubles the count
  Trainer split(scene_, config);
  for (int i = 0; i < 199; ++i) split.step(false);
  EXPECT_EQ(split.numGaussians(), start);
  split.step(false);  // iteration 200: the first round after densify_until
  EXPECT_EQ(split.numGaussians(), 2 * start);
  split.checkConsistency();
  config.large_split_last = 100;  // no round in the last 100 iterations: none at 200 of 250
  Trainer late(scene_, config);
  for (int i = 0; i < 250; ++i) late.step(false);
  EXPECT_EQ(late.numGaussians(), start);
}

// scale_limit bounds every Gaussian's scale by the limit x the scene extent after every step; off,
// the scales grow past it (the bound is what keeps them, not the scene).
TEST_P(TrainerOnDevice, TheScaleLimitBoundsEveryGaussiansScale) {
  const double extent = sceneExtent();
  TrainConfig config = small(60);
  const auto largest = [](const Trainer& t) {
    return t.parameters().log_scales.detach().max().exp().item<double>();
  };
  config.scale_limit = 0;  // off
  Trainer free(scene_, config);
  const double limit = 0.5 * largest(free) / extent;  // half the largest initial scale
  for (int i = 0; i < 60; ++i) free.step(false);
  EXPECT_GT(largest(free), limit * extent * 1.05);

  config.scale_limit = limit;
  config.scale_limit_from = 0;  // from the start
  Trainer bounded(scene_, config);
  for (int i = 0; i < 60; ++i) {
    bounded.step(false);
    ASSERT_LE(largest(bounded), limit * extent) << "after step " << i + 1;
  }
  const auto stats = bounded.step();
  EXPECT_TRUE(std::isfinite(stats.rgb_loss));
}

// The flatness loss shrinks every Gaussian's smallest scale (discs on the surfaces) and leaves
// the photometric fit working.
TEST_P(TrainerOnDevice, TheFlatnessLossMakesDiscs) {
  const auto smallestOverLargest = [](const Trainer& t) {
    const at::Tensor s = t.parameters().log_scales.detach().exp();
    return (std::get<0>(s.min(1)) / std::get<0>(s.max(1))).mean().item<double>();
  };
  TrainConfig config = small(60);
  Trainer plain(scene_, config);
  config.lambda_flatten = 100;
  Trainer flat(scene_, config);
  const double start = smallestOverLargest(flat);
  EXPECT_NEAR(start, smallestOverLargest(plain), 1e-12);
  for (int i = 0; i < 60; ++i) {
    plain.step(false);
    flat.step(false);
  }
  EXPECT_LT(smallestOverLargest(flat), 0.8 * smallestOverLargest(plain))
      << "start " << start << " plain " << smallestOverLargest(plain);
  EXPECT_TRUE(std::isfinite(flat.step().rgb_loss));
}

// The sparse-depth loss ties the rendered depth to the scene's points: Gaussians started at
// random (not on the points) end nearer the points' depths with it than without it.
TEST_P(TrainerOnDevice, TheSparseDepthLossPullsTheSurfacesToThePoints) {
  const at::Tensor points = gaussians::sparsePointTensor(scene_);
  ASSERT_TRUE(points.defined());
  const auto depthError = [&](const Trainer& t) {
    double sum = 0;
    int n = 0;
    for (const io::View& v : scene_.views) {
      if (!v.train) continue;
      const auto camera = gaussians::RasterCamera::fromPinhole(v.camera);
      gaussians::SparseDepthSamples s = gaussians::visibleSparseDepths(points, camera);
      const at::Tensor depth = t.renderDepth(camera).depth.detach();
      s.pixels = s.pixels.to(depth.device());
      s.depths = s.depths.to(depth.device());
      sum += gaussians::sparseDepthLoss(depth, s).item<double>();
      ++n;
    }
    return sum / n;
  };
  TrainConfig config = small(150);
  config.init = gaussians::InitMode::kRandom;
  config.init_random_count = 2000;
  Trainer plain(scene_, config);
  config.lambda_sparse_depth = 1;
  Trainer tied(scene_, config);
  const double start = depthError(tied);
  EXPECT_NEAR(start, depthError(plain), 1e-9);
  for (int i = 0; i < 150; ++i) {
    plain.step(false);
    tied.step(false);
  }
  EXPECT_LT(depthError(tied), 0.5 * depthError(plain))
      << "start " << start << " plain " << depthError(plain);
  EXPECT_TRUE(std::isfinite(tied.step().loss));
}

// scale_limit_from: no bound before that iteration; at it, the Gaussians above the limit are
// split (more rows, every state consistent) and from then on none exceeds it.
TEST_P(TrainerOnDevice, ALateScaleLimitSplitsTheLargeGaussiansFirst) {
  const double extent = sceneExtent();
  TrainConfig config = small(60);
  const auto largest = [](const Trainer& t) {
    return t.parameters().log_scales.detach().max().exp().item<double>();
  };
  const auto above = [](const Trainer& t, double bound) {
    return (std::get<0>(t.parameters().log_scales.detach().max(1)).exp() > bound)
        .sum()
        .item<std::int64_t>();
  };
  const double limit = 0.5 * largest(Trainer(scene_, config)) / extent;
  config.scale_limit = limit;
  config.scale_limit_from = 30;
  Trainer late(scene_, config);
  for (int i = 0; i < 29; ++i) late.step(false);
  const std::int64_t large = above(late, limit * extent);
  ASSERT_GT(large, 0) << "no Gaussian above the limit before it holds: the test shows nothing";
  const std::int64_t before = late.numGaussians();
  late.step(false);  // iteration 30: split, then clamped
  // Each split adds a row, a quarter of the model at most.
  EXPECT_GE(late.numGaussians(), before + std::min(large, before / 4));
  EXPECT_LE(late.numGaussians(), before + before / 4);
  EXPECT_LE(largest(late), limit * extent);
  late.checkConsistency();
  for (int i = 30; i < 60; ++i) {
    late.step(false);
    ASSERT_LE(largest(late), limit * extent) << "after step " << i + 1;
  }
  EXPECT_TRUE(std::isfinite(late.step().rgb_loss));
  // Every Gaussian above a tiny limit: the split stops at a quarter more rows; the clamp holds.
  config.scale_limit = 1e-6;
  Trainer tiny(scene_, config);
  for (int i = 0; i < 29; ++i) tiny.step(false);
  const std::int64_t rows = tiny.numGaussians();
  tiny.step(false);
  EXPECT_EQ(tiny.numGaussians(), rows + rows / 4);
  EXPECT_LE(largest(tiny), 1e-6 * extent);
  tiny.checkConsistency();
  // The default: a limit of 0.1 x the extent from iterations - iterations / 7 on.
  const Trainer by_default(scene_, small(70));
  EXPECT_EQ(by_default.config().scale_limit, 0.1);
  EXPECT_EQ(by_default.config().scale_limit_from, 60);
}

// Adam drove log-scales to -51.7 over a 30k schedule, and the training ended with an error instead
// of its model.ply (the writer refuses what the readers refuse, |log-scale| > 50): every step keeps
// them within e^+-20 of the scene extent.
TEST_P(TrainerOnDevice, LogScalesStayWithinTheBoundsTheModelReadersAccept) {
  const double log_extent = std::log(sceneExtent());
  TrainConfig config = small(10);
  config.scale_limit = 0;  // the upper bound here is the span's, not the scale limit's
  Trainer trainer(scene_, config);
  trainer.step(false);
  const at::Tensor log_scales = trainer.parameters().log_scales.detach();
  log_scales[0].fill_(-60.0);  // shares the trainer's storage
  log_scales[1].fill_(60.0);
  trainer.step(false);
  const at::Tensor after = trainer.parameters().log_scales.detach().cpu();
  EXPECT_NEAR(after.min().item<double>(), log_extent - 20, 1e-4);
  EXPECT_NEAR(after.max().item<double>(), log_extent + 20, 1e-4);
  test::TempDir dir;
  io::writeGaussians(dir.file("model.ply"), trainer.toCloud());
  EXPECT_EQ(io::readGaussians(dir.file("model.ply")).size(),
            static_cast<std::size_t>(trainer.numGaussians()));
}

// Gives every unlabelled training view one kept pseudo-label target per class (from its label
// map); returns how many views got them.
int pseudoLabelTheUnlabelledViews(io::Scene& scene) {
  int unlabelled = 0;
  for (io::View& v : scene.views) {
    if (!v.train || v.labelled) continue;
    ++unlabelled;
    io::ViewPseudoLabels& p = v.pseudo;
    p.num_classes = static_cast<int>(scene.classes.size());
    p.num_targets = p.num_classes;
    p.region.resize(v.labels.pixels.size());
    for (std::size_t i = 0; i < p.region.size(); ++i) {
      p.region[i] = v.labels.pixels[i] == io::kIgnoreLabel ? -1 : v.labels.pixels[i];
    }
    p.scores.assign(p.num_targets * p.num_classes, 0.0f);
    for (int t = 0; t < p.num_targets; ++t) p.scores[t * p.num_classes + t] = 1.0f;
    p.kept.assign(p.num_targets, 1);
  }
  return unlabelled;
}

// Pseudo-labels supervise the unlabelled training views: count the steps with a semantic loss;
// with no extra labelled render (semantic_interval 0) only the drawn view counts.
TEST_P(TrainerOnDevice, PseudoLabelsSuperviseTheUnlabelledTrainingViews) {
  const int unlabelled = pseudoLabelTheUnlabelledViews(scene_);
  ASSERT_GT(unlabelled, 0);
  auto steps_with_semantic_loss = [&](bool use_pseudo, int* pseudo_views) {
    TrainConfig c = small(24);
    c.semantic_interval = 0;
    c.use_pseudo_labels = use_pseudo;
    Trainer trainer(scene_, c);
    int n = 0;
    for (int i = 0; i < 24; ++i) {
      const auto stats = trainer.step();
      n += stats.semantic_loss > 0;
      *pseudo_views = stats.pseudo_labelled_views;
    }
    return n;
  };
  int pseudo_views = -1;
  EXPECT_EQ(steps_with_semantic_loss(true, &pseudo_views), 24);
  EXPECT_EQ(pseudo_views, unlabelled);
  EXPECT_LT(steps_with_semantic_loss(false, &pseudo_views), 24);
  EXPECT_EQ(pseudo_views, 0);
}

// pseudo_labels_train_decoder = false: the pseudo-labelled views' semantic loss moves the
// Gaussians' features but leaves the decoder exactly as it was (ground truth off here, so only
// pseudo-labels give semantic gradients); with true both move.
TEST_F(TrainerTest, PseudoLabelsCanLeaveTheDecoderToGroundTruth) {
  ASSERT_GT(pseudoLabelTheUnlabelledViews(scene_), 0);
  test::TempDir tmp;
  const std::string dir = tmp.path();
  auto run = [&](bool train_decoder, double* decoder_change, double* feature_change) {
    TrainConfig c = small(12);
    c.semantic_interval = 0;
    c.lambda_semantic = 0;
    c.pseudo_labels_train_decoder = train_decoder;
    Trainer trainer(scene_, c);
    trainer.saveCheckpoint(dir + "/before.ckpt");
    for (int i = 0; i < 12; ++i) trainer.step();
    trainer.saveCheckpoint(dir + "/after.ckpt");
    const auto before = gaussians::readTensorArchive(dir + "/before.ckpt");
    const auto after = gaussians::readTensorArchive(dir + "/after.ckpt");
    *decoder_change = 0;
    for (const char* name : {"decoder_w", "decoder_b"}) {
      *decoder_change +=
          (after.tensor(name, "after") - before.tensor(name, "before")).abs().sum().item<double>();
    }
    // No densification here, so the Gaussians keep their order and count.
    *feature_change = (after.tensor("features", "after") - before.tensor("features", "before"))
                          .abs()
                          .sum()
                          .item<double>();
  };
  double decoder_change = -1, feature_change = -1;
  run(false, &decoder_change, &feature_change);
  EXPECT_EQ(decoder_change, 0.0);
  EXPECT_GT(feature_change, 0.0);
  run(true, &decoder_change, &feature_change);
  EXPECT_GT(decoder_change, 0.0);
  EXPECT_GT(feature_change, 0.0);
}

TEST_P(TrainerOnDevice, DensificationAndPruningKeepTensorsAndOptimiserStateConsistent) {
  TrainConfig c = small(120);
  c.densify_from = 10;
  c.densify_interval = 20;
  c.densify_until = 100;
  c.densify_grad_threshold = 1e-7;  // force clones and splits
  c.percent_dense = 0.02;
  Trainer trainer(scene_, c);
  const auto before = trainer.numGaussians();
  for (int i = 0; i < 120; ++i) {
    trainer.step();
    trainer.checkConsistency();
  }
  EXPECT_GT(trainer.numGaussians(), before);
  const auto p = trainer.parameters();
  EXPECT_TRUE(at::isfinite(p.means).all().item<bool>());
  EXPECT_EQ(trainer.toCloud().size(), static_cast<std::size_t>(trainer.numGaussians()));
}

// A drop strategy whose evaluation gate is closed for every Gaussian at an even index (and that
// never drops on its own): what the trainer does with closed gates, isolated.
class EvenGatesClosed : public gaussians::DropStrategy {
 public:
  at::Tensor trainingGate(const at::Tensor&, int) const override { return {}; }
  at::Tensor evaluationGate(const at::Tensor& log_alpha) const override {
    return (at::arange(log_alpha.size(0), log_alpha.options().dtype(at::kLong)) % 2)
        .to(log_alpha.dtype());
  }
  at::Tensor regularisation(const at::Tensor&, int, const at::Tensor&) const override { return {}; }
  bool dropNow(int) const override { return false; }
  gaussians::DropDecision decide(const gaussians::DropInputs&, int) const override { return {}; }
};

TEST_P(TrainerOnDevice, FloatersArePrunedAtTheEndOnlyWhenAsked) {
  TrainConfig c = small(10);
  Trainer plain(scene_, c);
  gaussians::StepStats last;
  for (int i = 0; i < 10; ++i) last = plain.step();
  EXPECT_EQ(last.removed_floaters, 0);
  // The mask the end of training will apply: scales above the median (a fraction of the scene
  // extent) or centres outside every training view but one.
  std::vector<gaussians::RasterCamera> all, training;
  for (const io::View& v : scene_.views) {
    all.push_back(gaussians::RasterCamera::fromPinhole(v.camera));
    if (v.train) training.push_back(all.back());
  }
  const double extent = gaussians::sceneExtent(all);
  const gaussians::GaussianParams g = plain.parameters();
  const at::Tensor largest = std::get<0>(g.log_scales.detach().max(1)).exp().cpu();
  const double median = largest.median().item<double>();
  const std::int64_t expected =
      gaussians::floaterMask(g.means, g.log_scales, training, 2, median).sum().item<std::int64_t>();
  ASSERT_GT(expected, 0);
  ASSERT_LT(expected, plain.numGaussians());

  c.prune_floaters = true;
  c.floater_min_views = 2;
  c.floater_max_scale = median / extent;
  Trainer pruned(scene_, c);
  for (int i = 0; i < 10; ++i) last = pruned.step();
  pruned.checkConsistency();
  // The same training up to the end (CPU: bit for bit; CUDA: to rounding, so near the median a
  // Gaussian may fall on the other side).
  const double slack = GetParam() == "cpu" ? 0 : 0.02 * expected;
  EXPECT_NEAR(last.removed_floaters, expected, slack);
  EXPECT_EQ(pruned.numGaussians(), plain.numGaussians() - last.removed_floaters);
}

TEST_P(TrainerOnDevice, ClosedGatesArePrunedByDensificationAndAtTheEnd) {
  TrainConfig c = small(30);
  c.densify_from = 5;
  c.densify_interval = 10;
  c.densify_until = 15;
  c.densify_grad_threshold = 1e9;  // no clones or splits: only pruning
  c.opacity_reset_interval = 0;
  // Without a drop strategy nothing is transparent enough to be pruned.
  Trainer plain(scene_, c);
  const std::int64_t n0 = plain.numGaussians();
  for (int i = 0; i < 30; ++i) EXPECT_EQ(plain.step().removed_closed_gates, 0);
  EXPECT_EQ(plain.numGaussians(), n0);

  Trainer gated(scene_, c);
  gated.setDropStrategy(std::make_shared<EvenGatesClosed>());
  std::int64_t after_densify = -1;
  gaussians::StepStats last;
  for (int i = 0; i < 30; ++i) {
    last = gated.step();
    gated.checkConsistency();
    if (last.iteration == 10) after_densify = last.num_gaussians;
    if (last.iteration < 30) {
      EXPECT_EQ(last.removed_closed_gates, 0);
    }
  }
  EXPECT_EQ(after_densify, n0 / 2) << "densification prunes by opacity x evaluation gate";
  const std::int64_t n1 = n0 / 2;
  EXPECT_EQ(last.removed_closed_gates, n1 - n1 / 2);
  EXPECT_EQ(gated.numGaussians(), n1 / 2);
  EXPECT_EQ(gated.toCloud().size(), static_cast<std::size_t>(n1 / 2));
}

// Gates for the recovery phase's test: every third Gaussian's evaluation gate closed, every
// third half open, the rest open; a training gate of 0.9 and an L0 term of 10 (so a step's loss
// tells whether the gates were on); dropNow records when it was asked.
class ThirdsGates : public gaussians::DropStrategy {
 public:
  at::Tensor trainingGate(const at::Tensor& log_alpha, int) const override {
    return at::full_like(log_alpha, 0.9) + 0 * log_alpha;
  }
  at::Tensor evaluationGate(const at::Tensor& log_alpha) const override {
    const at::Tensor third =
        at::arange(log_alpha.size(0), log_alpha.options().dtype(at::kLong)) % 3;
    return (third.to(log_alpha.dtype()) * 0.5).to(log_alpha.device());
  }
  at::Tensor regularisation(const at::Tensor& log_alpha, int, const at::Tensor&) const override {
    return 10 + 0 * log_alpha.sum();
  }
  bool dropNow(int done) const override {
    asked->push_back(done);
    return false;
  }
  gaussians::DropDecision decide(const gaussians::DropInputs&, int) const override { return {}; }
  std::shared_ptr<std::vector<int>> asked = std::make_shared<std::vector<int>>();
};

TEST_P(TrainerOnDevice, RecoveryFoldsTheGatesIntoTheOpacitiesAndTrainsWithoutThem) {
  TrainConfig c = small(20);
  c.recovery_iterations = 5;
  c.lr_opacity = 0;                           // the opacities change only by the folding
  c.drop_rule = gaussians::DropRule::kPaper;  // the L0 term is in the loss
  Trainer trainer(scene_, c);
  auto gates = std::make_shared<ThirdsGates>();
  trainer.setDropStrategy(gates);
  const std::int64_t n = trainer.numGaussians();
  at::Tensor opacity_before;
  for (int i = 1; i <= 20; ++i) {
    if (i == 15) opacity_before = at::sigmoid(trainer.parameters().opacity_logits.detach()).cpu();
    const gaussians::StepStats s = trainer.step();
    trainer.checkConsistency();
    EXPECT_EQ(s.recovery_started, i == 15);
    if (i <= 15) {
      EXPECT_GT(s.loss, 10) << "iteration " << i << " trains with the L0 term";
    } else {
      EXPECT_LT(s.loss, 10) << "iteration " << i << " trains without it";
    }
    if (i == 15) {
      EXPECT_EQ(s.recovery_closed_gates, (n + 2) / 3);
      EXPECT_EQ(s.recovery_pruned, 0);
      EXPECT_EQ(s.num_gaussians, n - (n + 2) / 3);
    }
  }
  // Drops are asked for before the recovery only; none of the closed gates is left at the end.
  EXPECT_EQ(gates->asked->back(), 15);
  EXPECT_EQ(trainer.numGaussians(), n - (n + 2) / 3);
  // Folded: opacity x gate (0.5 or 1) of the Gaussians that stayed, in their order.
  const at::Tensor kept = (at::arange(n) % 3) != 0;
  const at::Tensor gate = ((at::arange(n) % 3).to(at::kFloat) * 0.5).index({kept});
  const at::Tensor expected = opacity_before.index({kept}) * gate;
  const at::Tensor after = at::sigmoid(trainer.parameters().opacity_logits.detach()).cpu();
  EXPECT_TRUE(at::allclose(after, expected, 1e-4, 1e-6));
}

TEST_P(TrainerOnDevice, RecoveryPruneRemovesTheShareThatContributesLeast) {
  TrainConfig c = small(12);
  c.recovery_iterations = 2;
  c.recovery_prune = 0.4;
  Trainer trainer(scene_, c);
  trainer.setDropStrategy(std::make_shared<ThirdsGates>());
  const std::int64_t n = trainer.numGaussians();
  gaussians::StepStats s;
  for (int i = 0; i < 10; ++i) s = trainer.step();
  ASSERT_TRUE(s.recovery_started);
  const std::int64_t open = n - (n + 2) / 3;
  EXPECT_EQ(s.recovery_pruned, static_cast<std::int64_t>(std::floor(0.4 * open)));
  EXPECT_EQ(s.num_gaussians, open - s.recovery_pruned);
  trainer.checkConsistency();
  for (int i = 0; i < 2; ++i) trainer.step();
  EXPECT_EQ(trainer.numGaussians(), open - s.recovery_pruned);
}

TEST_F(TrainerTest, RecoveryPruneWorksWithoutADrop) {
  TrainConfig c = small(6);
  c.recovery_iterations = 2;
  c.recovery_prune = 0.5;
  Trainer trainer(scene_, c);
  const std::int64_t n = trainer.numGaussians();
  gaussians::StepStats s;
  for (int i = 0; i < 4; ++i) s = trainer.step();
  EXPECT_TRUE(s.recovery_started);
  EXPECT_EQ(s.recovery_closed_gates, 0);
  EXPECT_EQ(s.recovery_pruned, n / 2);
  EXPECT_EQ(trainer.numGaussians(), n - n / 2);
  for (int i = 0; i < 2; ++i) trainer.step();
  trainer.checkConsistency();
}

// Open gates, no drops; regularisation records the L0 weights the trainer passes at each iteration.
class L0WeightRecorder : public gaussians::DropStrategy {
 public:
  at::Tensor trainingGate(const at::Tensor&, int) const override { return {}; }
  at::Tensor evaluationGate(const at::Tensor& log_alpha) const override {
    return at::ones_like(log_alpha);
  }
  at::Tensor regularisation(const at::Tensor&, int, const at::Tensor& l0_weights) const override {
    seen->push_back(l0_weights.defined() ? l0_weights.cpu().clone() : at::Tensor());
    return {};
  }
  bool dropNow(int) const override { return false; }
  gaussians::DropDecision decide(const gaussians::DropInputs&, int) const override { return {}; }
  std::shared_ptr<std::vector<at::Tensor>> seen = std::make_shared<std::vector<at::Tensor>>();
};

std::vector<gaussians::RasterCamera> trainingCameras(const io::Scene& scene) {
  std::vector<gaussians::RasterCamera> cameras;
  for (const io::View& v : scene.views) {
    if (v.train) cameras.push_back(gaussians::RasterCamera::fromPinhole(v.camera));
  }
  return cameras;
}

TEST_F(TrainerTest, L0WeightsFollowTheContributionsFromTheScheduleStartOnEveryDropInterval) {
  TrainConfig c = small(8);
  c.l0_importance = 1.0;
  c.lambda_l0_from = 3;
  c.drop_interval = 2;
  c.drop_rule = gaussians::DropRule::kPaper;  // the weights reach the L0 term of the loss
  Trainer trainer(scene_, c);
  auto recorder = std::make_shared<L0WeightRecorder>();
  trainer.setDropStrategy(recorder);
  std::vector<at::Tensor> expected(8);
  for (int it = 0; it < 8; ++it) {
    if (it == 3 || it == 5 || it == 7) {
      // What the weights must be: from the contributions of the Gaussians as they are now.
      expected[it] = gaussians::inverseContributionWeights(
          gaussians::blendingWeightSums(trainer.parameters(), trainingCameras(scene_)), 1.0);
    }
    trainer.step();
  }
  const std::vector<at::Tensor>& seen = *recorder->seen;
  ASSERT_EQ(seen.size(), 8u);
  for (int it = 0; it < 8; ++it) {
    ASSERT_TRUE(seen[it].defined()) << it;
    ASSERT_EQ(seen[it].size(0), trainer.numGaussians());
    if (it < 3) {
      EXPECT_TRUE(at::equal(seen[it], at::ones_like(seen[it]))) << "before the schedule: " << it;
    } else if (expected[it].defined()) {
      EXPECT_TRUE(at::allclose(seen[it], expected[it], 1e-5, 1e-6)) << "recomputed at " << it;
      EXPECT_GT((seen[it] - 1).abs().max().item<double>(), 0.1) << it;
    } else {
      EXPECT_TRUE(at::equal(seen[it], seen[it - 1])) << "kept between recomputations: " << it;
    }
  }
  EXPECT_FALSE(at::equal(seen[5], seen[3]));
}

TEST_F(TrainerTest, WithoutL0ImportanceTheL0TermGetsNoWeights) {
  TrainConfig c = small(3);
  c.drop_rule = gaussians::DropRule::kPaper;  // the L0 term of the loss
  Trainer trainer(scene_, c);
  auto recorder = std::make_shared<L0WeightRecorder>();
  trainer.setDropStrategy(recorder);
  for (int it = 0; it < 3; ++it) trainer.step();
  ASSERT_EQ(recorder->seen->size(), 3u);
  for (const at::Tensor& w : *recorder->seen) EXPECT_FALSE(w.defined());
}

TEST_F(TrainerTest, ResumeBetweenL0WeightUpdatesIsExact) {
  TrainConfig c = small(9);
  c.l0_importance = 2.0;
  c.lambda_l0_from = 2;
  c.drop_interval = 4;
  c.drop_rule = gaussians::DropRule::kPaper;  // the weights reach the L0 term of the loss
  auto run = [&](Trainer& t, int steps) {
    auto recorder = std::make_shared<L0WeightRecorder>();
    t.setDropStrategy(recorder);
    for (int i = 0; i < steps; ++i) t.step();
    return recorder->seen;
  };
  Trainer straight(scene_, c);
  const auto all = run(straight, 9);
  test::TempDir dir;
  {
    Trainer first(scene_, c);
    run(first, 4);  // weights computed at 2, next at 6
    first.saveCheckpoint(dir.file("ckpt.bin"));
  }
  Trainer resumed(scene_, c);
  resumed.loadCheckpoint(dir.file("ckpt.bin"));
  const auto rest = run(resumed, 5);
  ASSERT_EQ(rest->size(), 5u);
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(at::equal((*rest)[k], (*all)[4 + k])) << 4 + k;
  EXPECT_TRUE(at::equal(straight.parameters().means, resumed.parameters().means));
}

// The snapshot a checkpoint is written from on another thread is a copy: steps taken after it
// (the optimiser updates the parameters and moments in place) leave it as it was, and a trainer
// restored from it continues exactly like the one it was taken from.
TEST_F(TrainerTest, CheckpointSnapshotIsACopyTheTrainingDoesNotChange) {
  TrainConfig c = small(6);
  Trainer trainer(scene_, c);
  for (int i = 0; i < 2; ++i) trainer.step();
  const TensorArchive snapshot = trainer.checkpointSnapshot();
  std::map<std::string, at::Tensor> kept;
  for (const auto& [name, t] : snapshot.tensors) kept[name] = t.clone();
  const at::Tensor means_then = trainer.parameters().means.clone();
  for (int i = 0; i < 2; ++i) trainer.step();
  ASSERT_FALSE(at::equal(trainer.parameters().means, means_then));  // the steps moved them
  ASSERT_FALSE(kept.empty());
  for (const auto& [name, t] : snapshot.tensors) {
    EXPECT_TRUE(at::equal(t, kept[name])) << name << " changed after the snapshot";
  }
  test::TempDir dir;
  gaussians::writeTensorArchive(dir.file("ckpt.bin"), snapshot);
  Trainer resumed(scene_, c);
  resumed.loadCheckpoint(dir.file("ckpt.bin"));
  EXPECT_TRUE(at::equal(resumed.parameters().means, means_then));
  for (int i = 0; i < 2; ++i) resumed.step();
  EXPECT_TRUE(at::equal(resumed.parameters().means, trainer.parameters().means));
}

TEST_F(TrainerTest, ResumeAcrossTheRecoveryIsExact) {
  TrainConfig c = small(16);
  c.recovery_iterations = 8;
  c.recovery_prune = 0.2;
  Trainer straight(scene_, c);
  straight.setDropStrategy(std::make_shared<ThirdsGates>());
  for (int i = 0; i < 16; ++i) straight.step();
  test::TempDir dir;
  {
    Trainer first(scene_, c);
    first.setDropStrategy(std::make_shared<ThirdsGates>());
    for (int i = 0; i < 11; ++i) first.step();
    first.saveCheckpoint(dir.file("ckpt.bin"));
  }
  Trainer resumed(scene_, c);
  resumed.setDropStrategy(std::make_shared<ThirdsGates>());
  resumed.loadCheckpoint(dir.file("ckpt.bin"));
  for (int i = 0; i < 5; ++i) resumed.step();
  const auto a = straight.parameters(), b = resumed.parameters();
  ASSERT_EQ(a.means.size(0), b.means.size(0));
  EXPECT_TRUE(at::equal(a.means, b.means));
  EXPECT_TRUE(at::equal(a.opacity_logits, b.opacity_logits));
  EXPECT_TRUE(at::equal(a.features, b.features));
}

TEST_F(TrainerTest, ResumeFromACheckpointIsExact) {
  TrainConfig c = small(40);
  c.densify_from = 5;
  c.densify_interval = 10;
  c.densify_until = 35;
  c.densify_grad_threshold = 1e-6;
  Trainer straight(scene_, c);
  for (int i = 0; i < 40; ++i) straight.step();

  test::TempDir dir;
  {
    Trainer first(scene_, c);
    for (int i = 0; i < 20; ++i) first.step();
    first.saveCheckpoint(dir.file("ckpt.bin"));
  }
  Trainer resumed(scene_, c);
  resumed.loadCheckpoint(dir.file("ckpt.bin"));
  EXPECT_EQ(resumed.iteration(), 20);
  for (int i = 0; i < 20; ++i) resumed.step();
  const auto a = straight.parameters(), b = resumed.parameters();
  ASSERT_EQ(a.means.size(0), b.means.size(0));
  EXPECT_TRUE(at::equal(a.means, b.means));
  EXPECT_TRUE(at::equal(a.sh, b.sh));
  EXPECT_TRUE(at::equal(a.opacity_logits, b.opacity_logits));
  EXPECT_TRUE(at::equal(a.features, b.features));
}

TEST_F(TrainerTest, StepsThatDoNotReadTheLossesTrainTheSame) {
  TrainConfig c = small(30);
  c.densify_from = 5;
  c.densify_interval = 10;
  c.densify_grad_threshold = 1e-6;
  Trainer reading(scene_, c), quiet(scene_, c);
  gaussians::StepStats read_stats, quiet_stats;
  for (int i = 0; i < 30; ++i) {
    read_stats = reading.step(true);
    quiet_stats = quiet.step(i == 29 || i == 14);
    if (i == 13) {
      EXPECT_FALSE(quiet_stats.losses_read);
      EXPECT_TRUE(std::isnan(quiet_stats.loss) && std::isnan(quiet_stats.rgb_loss));
      EXPECT_TRUE(read_stats.losses_read);
      EXPECT_TRUE(std::isfinite(read_stats.loss));
    }
    if (i == 14) {
      EXPECT_DOUBLE_EQ(quiet_stats.loss, read_stats.loss);
    }
  }
  EXPECT_TRUE(quiet_stats.losses_read);
  EXPECT_DOUBLE_EQ(quiet_stats.loss, read_stats.loss);
  EXPECT_DOUBLE_EQ(quiet_stats.rgb_loss, read_stats.rgb_loss);
  EXPECT_EQ(quiet_stats.num_gaussians, read_stats.num_gaussians);
  const auto a = reading.parameters(), b = quiet.parameters();
  ASSERT_EQ(a.means.size(0), b.means.size(0));
  EXPECT_TRUE(at::equal(a.means, b.means));
  EXPECT_TRUE(at::equal(a.features, b.features));
}

// CUDA: tile lists sized from earlier renders train as exact lists do. With margin 1 (count +
// 1024 entries) densification's growth makes lists short: those steps render again, exactly.
// CUDA's backward sums with atomics, so two trainings agree to rounding, not bit for bit.
TEST_F(TrainerTest, CudaTileListsSizedFromEarlierRendersTrainAsExactLists) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  TrainConfig c = small(60, "cuda");
  c.densify_from = 10;
  c.densify_until = 30;
  c.densify_interval = 10;
  // Every Gaussian is cloned at each densification: the counts double, past any list sized
  // before them. Nothing is split or pruned, so the count and the rows' order do not hang on
  // values that the GPU's atomic sums leave different in the last bits (a split/clone or
  // opacity decision at its threshold made this test fail now and then).
  c.densify_grad_threshold = 0;
  c.percent_dense = 1e6;
  c.min_opacity = 0;
  c.drop = gaussians::DropMode::kFull;  // gated renders: the second pass samples the same gates
  c.tile_list_margin = 1.0;
  TrainConfig exact_config = c;
  exact_config.tile_list_margin = 0;
  Trainer sized(scene_, c), exact(scene_, exact_config);
  int again = 0;
  for (int i = 0; i < 60; ++i) {
    const gaussians::StepStats s = sized.step(true), e = exact.step(true);
    EXPECT_FALSE(e.rendered_again);
    again += s.rendered_again ? 1 : 0;
    EXPECT_NEAR(s.loss, e.loss, 1e-3 * e.loss) << "step " << i;
  }
  EXPECT_GE(again, 1);
  EXPECT_LT(again, 30);
  const auto a = sized.parameters(), b = exact.parameters();
  ASSERT_EQ(a.means.size(0), b.means.size(0));
  EXPECT_LT((a.means - b.means).abs().max().item<double>(), 1e-3 * sceneExtent());
}

TEST_F(TrainerTest, BadCheckpointsAndConfigsAreClearErrors) {
  test::TempDir dir;
  test::writeFile(dir.file("bad.bin"), "not a checkpoint");
  Trainer trainer(scene_, small(5));
  EXPECT_THROW(trainer.loadCheckpoint(dir.file("bad.bin")), Error);
  EXPECT_THROW(trainer.loadCheckpoint(dir.file("missing.bin")), Error);
  try {
    TrainConfig::fromJson("{\"iterations\": 10, \"lr_warp\": 1}", "cfg.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "lr_warp");
  }
  EXPECT_THROW(TrainConfig::fromJson("{\"iterations\": \"many\"}", "cfg.json"), Error);
  // Numbers outside their field's type, a fraction for a count, a short colour: errors naming the
  // key (they were converted with undefined behaviour, or were internal errors).
  for (const char* bad :
       {"{\"iterations\": 1e300}", "{\"iterations\": 2147483648}", "{\"seed\": -1}",
        "{\"densify_from\": 2.5}", "{\"background\": [1, 2]}", "{\"background\": [1, 2, null]}"}) {
    EXPECT_THROW(TrainConfig::fromJson(bad, "cfg.json"), Error) << bad;
  }
  EXPECT_EQ(TrainConfig::fromJson("{\"seed\": 18446744073709551615}", "c").seed,
            18446744073709551615ull);
  EXPECT_EQ(TrainConfig::fromJson("{\"iterations\": 3.0}", "c").iterations, 3);
  // A tile-list margin between 0 (exact lists) and 1 would size lists below the last count.
  try {
    TrainConfig::fromJson("{\"tile_list_margin\": 0.5}", "cfg.json").check("cfg.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "tile_list_margin");
  }
  TrainConfig c;
  c.iterations = 123;
  c.background = {0.5f, 0.25f, 1.f};
  c.lambda_l0_from = 3500;
  c.lambda_l0_ramp = 700;
  const TrainConfig back = TrainConfig::fromJson(c.toJson(), "x");
  EXPECT_EQ(back.iterations, 123);
  EXPECT_EQ(back.background[1], 0.25f);
  EXPECT_EQ(back.lambda_l0_from, 3500);
  EXPECT_EQ(back.lambda_l0_ramp, 700);
  EXPECT_THROW(TrainConfig::fromJson("{\"device\": \"tpu\"}", "x"), Error);
}

// densify_until -1: 2/7 of the iterations, so the 7000-iteration schedule has no opacity reset
// inside its densification (the reset at 3000 cost Net-1 1.2-2.3 dB); a short run (no reset
// inside) densifies for half, said as a change of its schedule; a value set holds.
TEST(TrainConfigSchedule, DensificationEndsAtTwoSeventhsAndAShortRunDensifiesForHalf) {
  TrainConfig c;  // 7000 iterations, reset every 3000
  EXPECT_EQ(c.densify_until, -1);
  EXPECT_EQ(densifyUntilResolved(c), 2000);
  TrainConfig resolved = c;
  resolved.densify_until = densifyUntilResolved(c);
  EXPECT_FALSE(resetsOpacitiesAfter(resolved, 3000));
  resolved.densify_until = 3500;  // the old default: a reset 500 iterations before the end
  EXPECT_TRUE(resetsOpacitiesAfter(resolved, 3000));
  EXPECT_EQ(shortRunSchedule(c, {}).densify_until, -1);  // 7000 is not a short run
  c.iterations = 30000;
  EXPECT_EQ(densifyUntilResolved(c), 8571);
  c.densify_until = 3500;
  EXPECT_EQ(densifyUntilResolved(c), 3500);

  TrainConfig s;
  s.iterations = 600;
  std::vector<std::string> changed;
  const TrainConfig short_run = shortRunSchedule(s, {}, &changed);
  EXPECT_EQ(short_run.densify_until, 300);
  EXPECT_NE(std::find(changed.begin(), changed.end(), "densify_until -1 -> 300"), changed.end());
  EXPECT_EQ(densifyUntilResolved(shortRunSchedule(s, {"densify_until"})), 171);  // kept: -1
  s.densify_until = 100;
  EXPECT_EQ(shortRunSchedule(s, {}).densify_until, 100);
}

// The trainer runs (and a run's config.json records) the resolved end, not -1.
TEST_F(TrainerTest, TheTrainerRunsTheResolvedDensificationEnd) {
  TrainConfig c = small(70);
  const Trainer plain(scene_, c);
  EXPECT_EQ(plain.config().densify_until, 20);
  c.densify_until = 35;
  const Trainer given(scene_, c);
  EXPECT_EQ(given.config().densify_until, 35);
  // What `sadsplat train` says of it: the default 7000-iteration schedule has no opacity reset.
  TrainConfig d;
  d.checkpoint_interval = 0;
  EXPECT_EQ(describeDefaultDensification(Trainer(scene_, d).config()),
            "7000 iterations; densification after 500 until 2000 every 100; opacity reset none; "
            "scale limit 0.1 x the extent from 6000");
  d.densify_until = 3500;
  d.scale_limit = 0;
  EXPECT_EQ(describeDefaultDensification(Trainer(scene_, d).config()),
            "7000 iterations; densification after 500 until 3500 every 100; opacity reset at 3000");
  d.opacity_reset_interval = 100;  // many resets: a range, not a list
  EXPECT_EQ(describeDefaultDensification(Trainer(scene_, d).config()),
            "7000 iterations; densification after 500 until 3500 every 100; opacity reset every "
            "100 from 100 to 3500");
  // No reset in the last third of an interval: densifying until the end, a reset after the
  // last iteration (or 900 before it) would leave every opacity at 0.01.
  d.iterations = 9000;
  d.densify_until = 9000;
  d.opacity_reset_interval = 3000;
  EXPECT_EQ(describeDefaultDensification(Trainer(scene_, d).config()),
            "9000 iterations; densification after 500 until 9000 every 100; opacity reset at "
            "3000, 6000");
  d.iterations = 9900;  // 9000 is 900 before the end: not allowed
  EXPECT_EQ(describeDefaultDensification(Trainer(scene_, d).config()),
            "9900 iterations; densification after 500 until 9000 every 100; opacity reset at "
            "3000, 6000");
  d.iterations = 10000;  // 1000 after 9000: allowed
  EXPECT_EQ(describeDefaultDensification(Trainer(scene_, d).config()),
            "10000 iterations; densification after 500 until 9000 every 100; opacity reset at "
            "3000, 6000, 9000");
  EXPECT_EQ(describeDefaultDensification(plain.config()),
            "70 iterations; no densification; opacity reset none; scale limit 0.1 x the extent "
            "from 60");
}

// Densifying until the end with a reset interval that divides the run: the reset after the
// last iteration (and any in the last third of an interval) is skipped, one with room after it
// happens. Before, the model came out with every opacity at 0.01.
TEST_F(TrainerTest, NoOpacityResetWithoutRoomToRecoverBeforeTheEnd) {
  TrainConfig c = small(60);
  c.densify_until = 60;
  c.opacity_reset_interval = 30;
  Trainer trainer(scene_, c);
  const auto max_opacity = [&] {
    return at::sigmoid(trainer.parameters().opacity_logits.detach()).max().item<double>();
  };
  for (int i = 1; i <= 60; ++i) {
    trainer.step();
    if (i == 30) EXPECT_LE(max_opacity(), 0.0100001) << "the reset after iteration 30 happens";
  }
  EXPECT_GT(max_opacity(), 0.011) << "no reset after the last iteration";
  EXPECT_FALSE(gaussians::resetsOpacitiesAfter(trainer.config(), 60));
  EXPECT_TRUE(gaussians::resetsOpacitiesAfter(trainer.config(), 30));
}

// A moving object (a magenta square, in another place in each of three training views) leaves a
// ghost in the model where it was seen, unless masks (io::View::mask, from masks/*.png at import)
// keep its pixels out of the losses: then the model shows there what a model trained without the
// object shows.
TEST_F(TrainerTest, MaskedPixelsOfAMovingObjectLeaveNoGhost) {
  struct Square {
    int view, x0, y0;
  };
  const std::vector<Square> squares = {{0, 18, 14}, {3, 30, 20}, {6, 24, 10}};
  const int side = 10;
  // How magenta the renders are over the squares, (R + B) / 2 - G averaged: trained on the clean
  // photos, with the object unmasked, with the object masked.
  double magenta[3] = {0, 0, 0};
  for (int variant = 0; variant < 3; ++variant) {
    io::Scene scene = scene_;
    for (const Square& q : squares) {
      io::View& v = scene.views[q.view];
      ASSERT_TRUE(v.train) << v.name;
      if (variant == 0) continue;
      for (int y = q.y0; y < q.y0 + side; ++y) {
        for (int x = q.x0; x < q.x0 + side; ++x) {
          const std::size_t p = static_cast<std::size_t>(y) * v.camera.width + x;
          v.rgb.pixels[3 * p] = 255, v.rgb.pixels[3 * p + 1] = 0, v.rgb.pixels[3 * p + 2] = 255;
          if (variant == 2) v.mask.pixels[p] = 0;
        }
      }
    }
    TrainConfig c = small(300);
    c.densify_from = 50;
    c.densify_until = 250;
    Trainer trainer(scene, c);
    for (int i = 0; i < 300; ++i) trainer.step(false);
    double sum = 0;
    for (const Square& q : squares) {
      const at::Tensor rgb = trainer.renderView(scene_.views[q.view])
                                 .rgb.cpu()
                                 .slice(0, q.y0, q.y0 + side)
                                 .slice(1, q.x0, q.x0 + side);
      sum += ((rgb.select(2, 0) + rgb.select(2, 2)) / 2 - rgb.select(2, 1)).mean().item<double>();
    }
    magenta[variant] = sum / squares.size();
  }
  std::printf(
      "magenta over the object's squares: %.3f trained without the object, %.3f with it, "
      "%.3f with it masked\n",
      magenta[0], magenta[1], magenta[2]);
  const double ghost = magenta[1] - magenta[0], masked_ghost = magenta[2] - magenta[0];
  EXPECT_GT(ghost, 0.1);                            // the object's ghost, unmasked
  EXPECT_LT(std::abs(masked_ghost), 0.25 * ghost);  // masked: about what the clean photos give
}

TEST(TrainConfigLong, TheLongScheduleIsLongerPrunesLateAndRefinesKeepingGivenKeys) {
  TrainConfig c;
  std::vector<std::string> changed;
  const TrainConfig net1 = longSchedule(c, {}, &changed);
  EXPECT_EQ(net1.iterations, 30000);
  EXPECT_EQ(net1.densify_until, 7500);  // the first quarter
  EXPECT_EQ(net1.lambda_l0_from, 0);    // no drop: no gate keys
  EXPECT_EQ(net1.recovery_iterations, 0);
  EXPECT_EQ(changed.size(), 2u);
  c.drop = gaussians::DropMode::kFull;
  const TrainConfig full = longSchedule(c, {});
  EXPECT_EQ(full.densify_until, 7500);
  EXPECT_EQ(full.lambda_l0_from, 7500);  // after the densification
  EXPECT_EQ(full.recovery_iterations, 5000);
  full.check();
  c.iterations = 12000;
  c.recovery_iterations = 100;
  const TrainConfig given = longSchedule(c, {"iterations", "recovery_iterations"});
  EXPECT_EQ(given.iterations, 12000);
  EXPECT_EQ(given.densify_until, 3000);
  EXPECT_EQ(given.lambda_l0_from, 3000);
  EXPECT_EQ(given.recovery_iterations, 100);
  c.densify_until = 4000;  // a densification end the user set holds, and the gates follow it
  const TrainConfig own = longSchedule(c, {"iterations", "densify_until"});
  EXPECT_EQ(own.densify_until, 4000);
  EXPECT_EQ(own.lambda_l0_from, 4000);
}

TEST(TrainConfigBatch, ASchedulePerGlobalBatchSeesAsManyViewsWithSqrtLearningRates) {
  TrainConfig c;  // defaults: 7000 iterations, densify 500 / 100, reset 3000, drop 500
  c.densify_until = -1;
  c.checkpoint_interval = 0;
  const TrainConfig b = forGlobalBatch(c, 4);
  EXPECT_EQ(b.iterations, 1750);
  EXPECT_EQ(b.densify_from, 125);
  EXPECT_EQ(b.densify_interval, 25);
  EXPECT_EQ(b.opacity_reset_interval, 750);
  EXPECT_EQ(b.sh_increase_interval, 250);
  EXPECT_EQ(b.drop_interval, 125);
  EXPECT_EQ(b.lambda_l0_from, 0);       // still the paper's constant weight
  EXPECT_EQ(b.densify_until, -1);       // still "2/7 of the iterations"
  EXPECT_EQ(b.checkpoint_interval, 0);  // still none
  EXPECT_DOUBLE_EQ(b.lr_opacity, 2 * c.lr_opacity);
  EXPECT_DOUBLE_EQ(b.lr_position_final, 2 * c.lr_position_final);
  EXPECT_DOUBLE_EQ(b.lr_log_alpha, 2 * c.lr_log_alpha);
  EXPECT_EQ(b.seed, c.seed);
  // Intervals never reach 0; one view per step is the configuration itself.
  c.densify_interval = 3;
  EXPECT_EQ(forGlobalBatch(c, 8).densify_interval, 1);
  EXPECT_EQ(forGlobalBatch(c, 1).toJson(), c.toJson());
  EXPECT_THROW(forGlobalBatch(c, 0), Error);
}

}  // namespace
}  // namespace sadsplat
