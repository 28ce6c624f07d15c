// pipeline::trainRun resolves the schedule once: what it prints, what config.json records, what
// run.json and the train log say the trainer ran, and gaussians::resolveSchedule agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "sadsplat/eval/evaluation.h"
#include "sadsplat/gaussians/densification.h"
#include "sadsplat/gaussians/schedule.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/train_log.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/ortho_render.h"
#include "sadsplat/pipeline/pseudo_label_run.h"
#include "sadsplat/pipeline/train_run.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using gaussians::ScheduleKind;
using gaussians::TrainConfig;

const std::string kCache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";

struct Case {
  const char* name;
  int iterations;
  ScheduleKind kind;
  std::vector<std::string> given;
  int views_per_step;
  int batch_ranks;
  bool run_to_end;  // the default and long schedules stop before their first step here
};

// ctest lists a parameter by this (not by its bytes).
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class ScheduleAgreement : public ::testing::TestWithParam<Case> {};

TEST_P(ScheduleAgreement, PrintedRecordedAndRunScheduleAreOne) {
  const Case& k = GetParam();
  test::TempDir dir;
  TrainConfig asked;
  asked.iterations = k.iterations;
  asked.views_per_step = k.views_per_step;
  asked.drop = gaussians::DropMode::kFull;
  pipeline::TrainRunOptions o;
  o.scene = kCache;
  o.out = dir.file("run");
  o.schedule.kind = k.kind;
  o.schedule.given = k.given;
  o.schedule.batch_ranks = k.batch_ranks;
  std::ostringstream progress;
  o.progress = &progress;
  std::atomic<bool> stop{!k.run_to_end};
  o.stop = &stop;
  bool interrupted = false;
  try {
    pipeline::trainRun(o, asked);
  } catch (const pipeline::TrainingInterrupted& e) {
    interrupted = true;
    EXPECT_EQ(e.iteration(), 0);
  }
  EXPECT_EQ(interrupted, !k.run_to_end);

  const TrainConfig recorded =
      TrainConfig::fromJson(io::readWholeFile(o.out + "/config.json"), o.out + "/config.json");
  const TrainConfig resolved = gaussians::resolveSchedule(asked, o.schedule).config;
  EXPECT_EQ(recorded.toJson(), resolved.toJson());
  EXPECT_GE(recorded.densify_until, 0);
  EXPECT_GE(recorded.scale_limit_from, 0);
  const std::string printed = progress.str();
  const std::string line = "schedule: " + gaussians::describeDefaultDensification(recorded) + "\n";
  EXPECT_NE(printed.find(line), std::string::npos) << printed;
  if (!k.run_to_end) return;
  const auto run = nlohmann::json::parse(io::readWholeFile(o.out + "/run.json"));
  EXPECT_EQ(run["iterations"].get<int>(), recorded.iterations);
  const auto log = io::readTrainLog(o.out + "/train_log.jsonl");
  ASSERT_FALSE(log.empty());
  EXPECT_EQ(log.back().iteration, recorded.iterations);
  const std::string last =
      "[" + std::to_string(recorded.iterations) + "/" + std::to_string(recorded.iterations) + "]";
  EXPECT_NE(printed.find(last), std::string::npos) << printed;
}

INSTANTIATE_TEST_SUITE_P(
    Schedules, ScheduleAgreement,
    ::testing::Values(Case{"paper", 7000, ScheduleKind::kPaper, {}, 1, 0, false},
                      Case{"short", 24, ScheduleKind::kPaper, {}, 1, 0, true},
                      Case{"long", 7000, ScheduleKind::kLong, {}, 1, 0, false},
                      Case{"long_given", 36, ScheduleKind::kLong, {"iterations"}, 1, 0, true},
                      Case{"batched", 40, ScheduleKind::kPaper, {}, 2, 1, true}),
    [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

// The batch rule divides what the short-run rules set (they run first), and a resolved
// configuration resolves to itself.
TEST(ResolveSchedule, RulesApplyInOrderAndOnce) {
  TrainConfig c;
  c.iterations = 40;
  c.views_per_step = 2;
  gaussians::ScheduleRequest request;
  request.batch_ranks = 1;
  const gaussians::ResolvedSchedule r = gaussians::resolveSchedule(c, request);
  EXPECT_EQ(r.config.iterations, 20);
  EXPECT_EQ(r.config.drop_interval, 5);   // short: 40 / 4 = 10, then / 2
  EXPECT_EQ(r.config.densify_until, 10);  // short: half of 40, then / 2
  EXPECT_EQ(r.config.scale_limit_from, 20 - 20 / 7);
  ASSERT_EQ(r.notes.size(), 2u);
  EXPECT_EQ(r.notes[1].rfind("global batch of 2 views per step", 0), 0u) << r.notes[1];
  EXPECT_EQ(gaussians::resolveDerivedKeys(r.config).toJson(), r.config.toJson());
  EXPECT_EQ(gaussians::resolveSchedule(TrainConfig{}).config.densify_until, 2000);
  EXPECT_EQ(gaussians::resolveSchedule(TrainConfig{}).config.scale_limit_from, 6000);
  EXPECT_TRUE(gaussians::resolveSchedule(TrainConfig{}).notes.empty());
  EXPECT_THROW(gaussians::parseScheduleKind("short"), Error);
}

}  // namespace
}  // namespace sadsplat

namespace sadsplat {
namespace {

// Streamed views (TrainConfig::stream_views) train the model that views held on the device
// train, both ways of streaming: views read from the scene cache by the loader threads ahead of
// the steps (trainRun on a cache path), and 8-bit host copies of a scene in memory (trainRun on
// a loaded scene); and views held on the device train the same whether they were read from the
// cache one at a time (trainRun on a cache path) or with the whole cache. Bit for bit on the CPU;
// on a GPU to the rounding of its backward's atomics (two held runs differ as much). The cache is
// the fixture with the built-in pseudo-labels, so the confidence maps and pseudo-label supervision
// come from the cache too.
void expectStreamedViewsTrainLikeHeldViews(const std::string& device) {
  test::TempDir dir;
  pipeline::PseudoLabelRunOptions labelling;
  labelling.scene = kCache;
  labelling.out = dir.file("pl.cache");
  pipeline::pseudoLabelRun(labelling);
  TrainConfig config;
  config.iterations = 40;
  config.device = gaussians::parseChoice<gaussians::TrainDevice>(device, "test", "device");
  config.drop = gaussians::DropMode::kFull;
  config.drop_interval = 20;
  config.checkpoint_interval = 0;
  pipeline::TrainRunOptions o;
  o.scene = dir.file("pl.cache");
  o.out = dir.file("held");  // the reference: the whole cache read, every view held
  pipeline::trainRun(o, config, io::readSceneCache(o.scene));
  o.out = dir.file("held_from_cache");  // held, each view read from the cache once
  pipeline::trainRun(o, config);
  config.stream_views = true;
  o.out = dir.file("from_cache");
  pipeline::trainRun(o, config);
  o.out = dir.file("host_copies");
  pipeline::trainRun(o, config, io::readSceneCache(o.scene));
  const std::string held = test::readFile(dir.file("held/model.ply"));
  for (const std::string run : {"held_from_cache", "from_cache", "host_copies"}) {
    const std::string streamed = test::readFile(dir.file(run + "/model.ply"));
    if (device == "cpu") {
      EXPECT_TRUE(held == streamed) << run << ": the same model, byte for byte";
      continue;
    }
    const auto a = io::readGaussianPly(dir.file("held/model.ply"));
    const auto b = io::readGaussianPly(dir.file(run + "/model.ply"));
    ASSERT_EQ(a.size(), b.size()) << run;
    double d = 0;
    for (std::size_t i = 0; i < a.size(); ++i) d += std::abs(a[i].x - b[i].x) / a.size();
    EXPECT_LT(d, 1e-4) << run;
  }
}

TEST(StreamedViews, TrainLikeHeldViewsOnTheCpu) { expectStreamedViewsTrainLikeHeldViews("cpu"); }

// A 10-iteration training of the fixture cache into `out`; returns its configuration.
TrainConfig trainTinyRun(const std::string& out) {
  TrainConfig config;
  config.iterations = 10;
  config.checkpoint_interval = 0;
  pipeline::TrainRunOptions o;
  o.scene = kCache;
  o.out = out;
  pipeline::trainRun(o, config);
  return config;
}

// A run opened for rendering (pipeline::openRun) holds only the cameras: it renders what a
// trainer that holds the views renders, and refuses to train.
TEST(OpenedRun, ATrainerForRenderingHoldsOnlyCamerasRendersAlikeAndRefusesToTrain) {
  test::TempDir dir;
  trainTinyRun(dir.file("run"));
  const pipeline::OpenedRun run = pipeline::openRun(dir.file("run"));
  const pipeline::OpenedRun loaded = pipeline::openRun(
      dir.file("run"), "", 0.5, pipeline::ScenePixels::kRead, gaussians::TrainerViews::kLoaded);
  for (const io::View& v : run.scene.views) {
    EXPECT_TRUE(run.trainer->renderView(v).rgb.equal(loaded.trainer->renderView(v).rgb)) << v.name;
  }
  EXPECT_THROW(run.trainer->step(), sadsplat::Error);
  EXPECT_NO_THROW(loaded.trainer->step());
}

// A run trained on a GPU (config.json: "device": "cuda") opens on a machine without one: the
// model renders on the CPU, as the same run trained there does.
TEST(OpenedRun, ARunTrainedOnAGpuOpensOnTheCpuOfAMachineWithoutOne) {
  if (at::hasCUDA()) GTEST_SKIP() << "this machine has a CUDA device";
  test::TempDir dir;
  trainTinyRun(dir.file("run"));
  const pipeline::OpenedRun cpu = pipeline::openRun(dir.file("run"));
  std::string config = test::readFile(dir.file("run/config.json"));
  const std::size_t at = config.find("\"device\": \"cpu\"");
  ASSERT_NE(at, std::string::npos);
  config.replace(at, 15, "\"device\": \"cuda\"");
  io::writeTextFileAtomically(dir.file("run/config.json"), config);
  const pipeline::OpenedRun gpu_run = pipeline::openRun(dir.file("run"));
  EXPECT_EQ(gpu_run.config.device, gaussians::TrainDevice::kCpu);
  const io::View& v = cpu.scene.views.front();
  EXPECT_TRUE(gpu_run.trainer->renderView(v).rgb.equal(cpu.trainer->renderView(v).rgb));
}

// What a run hands out (model.ply, model_semantic, extract, eval --3d) labels each Gaussian by
// the classes its training views render where it draws (pipeline/labelled_cloud.h): the class
// with the largest blending weight; a Gaussian no training view draws keeps its feature's class;
// nothing but the label changes, and model.ply holds these labels.
TEST(LabelledCloud, EachGaussianTakesTheClassTheViewsRenderWhereItDraws) {
  test::TempDir dir;
  trainTinyRun(dir.file("run"));
  const pipeline::OpenedRun run = pipeline::openRun(dir.file("run"));
  const auto labelled = pipeline::labelledCloud(*run.trainer, run.scene);
  const auto own = run.trainer->toCloud();
  std::vector<gaussians::RasterCamera> cameras;
  for (const io::View& v : run.scene.views) {
    if (v.train) cameras.push_back(gaussians::RasterCamera::fromPinhole(v.camera));
  }
  const at::Tensor w = run.trainer->renderedClassWeights(cameras);
  ASSERT_EQ(w.size(0), static_cast<std::int64_t>(labelled.size()));
  ASSERT_EQ(w.size(1), run.trainer->numClasses());
  const auto written = io::readGaussianPly(dir.file("run/model.ply"));
  ASSERT_EQ(written.size(), labelled.size());
  int seen = 0;
  for (std::size_t i = 0; i < labelled.size(); ++i) {
    const at::Tensor row = w[static_cast<std::int64_t>(i)];
    if (row.sum().item<double>() > 0) {
      ++seen;
      EXPECT_EQ(labelled[i].label, static_cast<std::uint32_t>(row.argmax().item<std::int64_t>()))
          << i;
    } else {
      EXPECT_EQ(labelled[i].label, own[i].label) << i;
    }
    EXPECT_EQ(labelled[i].x, own[i].x);
    EXPECT_EQ(labelled[i].opacity, own[i].opacity);
    EXPECT_EQ(written[i].label, labelled[i].label) << i;
  }
  EXPECT_GT(seen, static_cast<int>(labelled.size()) / 2);
}

// Trainer::renderCameraWith composites any per-Gaussian rows as the features are composited: the
// model's own features give its render's features; one-hot classes give per pixel weights that
// sum to the alpha. `ortho --class-from views` (OrthoClassSource::kViews) takes the class with the
// most of that weight: every Gaussian of one class gives that class everywhere, at confidence 1.
TEST(LabelledCloud, OneHotClassesRenderAsBlendingWeightsAndMakeTheViewsClassMap) {
  test::TempDir dir;
  trainTinyRun(dir.file("run"));
  const pipeline::OpenedRun run = pipeline::openRun(dir.file("run"));
  const gaussians::Trainer& trainer = *run.trainer;
  const gaussians::RasterCamera cam =
      gaussians::RasterCamera::fromPinhole(run.scene.views.front().camera);
  const gaussians::RenderResult own = trainer.renderCamera(cam);
  const at::Tensor features = trainer.parameters().features;
  EXPECT_TRUE(
      at::allclose(trainer.renderCameraWith(cam, features).features, own.features, 1e-5, 1e-6));
  const int k = trainer.numClasses();
  const std::int64_t n = trainer.numGaussians();
  const at::Tensor labels = at::arange(n, at::kLong).remainder(k);
  const at::Tensor weights =
      trainer.renderCameraWith(cam, at::one_hot(labels, k).to(at::kFloat)).features;
  ASSERT_EQ(weights.size(2), k);
  EXPECT_TRUE(at::allclose(weights.sum(2), own.alpha, 1e-4, 1e-5));
  EXPECT_GT(own.alpha.max().item<double>(), 0.5);  // not an empty picture
  EXPECT_THROW(trainer.renderCameraWith(cam, at::zeros({n - 1, k})), Error);

  pipeline::OrthoRenderOptions options;
  options.classes = pipeline::OrthoClassSource::kViews;
  const pipeline::OrthoGrid grid = pipeline::footprintGrid(trainer, run.scene, 0.05);
  EXPECT_THROW(pipeline::renderOrtho(trainer, grid, options), Error);  // no classes given
  options.gaussian_classes.assign(static_cast<std::size_t>(n), static_cast<std::uint32_t>(k - 1));
  const pipeline::OrthoImages img = pipeline::renderOrtho(trainer, grid, options, nullptr, 16);
  std::size_t covered = 0;
  for (std::size_t c = 0; c < img.covered.size(); ++c) {
    if (!img.covered[c]) continue;
    ++covered;
    EXPECT_EQ(img.classes[c], k - 1) << c;
    EXPECT_NEAR(img.confidence[c], 1.0, 1e-5) << c;
  }
  EXPECT_GT(covered, 50u);  // the tiny model covers a few hundred cells
}

// `extract RUN --on-surface M` starts from gaussiansOnSurface: the run's model.ply without the
// Gaussians farther than M from the surface their views render (surfaceGaps, one per Gaussian);
// a large M keeps every Gaussian some view draws, a smaller one fewer.
TEST(LabelledCloud, OnTheSurfaceKeepsTheGaussiansWithinTheGap) {
  test::TempDir dir;
  trainTinyRun(dir.file("run"));
  const pipeline::OpenedRun run = pipeline::openRun(dir.file("run"));
  const auto labelled = pipeline::labelledCloud(*run.trainer, run.scene);
  const auto model = io::readGaussianPly(dir.file("run/model.ply"));  // labelled's labels
  const std::vector<float> gaps = pipeline::surfaceGaps(*run.trainer, run.scene);
  ASSERT_EQ(gaps.size(), labelled.size());
  std::vector<float> finite;
  for (float g : gaps) {
    EXPECT_GE(g, 0.f);
    if (std::isfinite(g)) finite.push_back(g);
  }
  ASSERT_GT(finite.size(), labelled.size() / 2);
  std::sort(finite.begin(), finite.end());
  const auto all = pipeline::gaussiansOnSurface(dir.file("run"), model, 1e30f);
  EXPECT_EQ(all.size(), finite.size());
  const float median = finite[finite.size() / 2];
  const auto near = pipeline::gaussiansOnSurface(dir.file("run"), model, median);
  std::size_t expected = 0, j = 0;
  for (std::size_t i = 0; i < labelled.size(); ++i) {
    if (!(gaps[i] <= median)) continue;
    ++expected;
    ASSERT_LT(j, near.size());
    EXPECT_EQ(near[j].x, labelled[i].x);
    EXPECT_EQ(near[j].label, labelled[i].label);
    ++j;
  }
  EXPECT_EQ(near.size(), expected);
  EXPECT_LT(near.size(), all.size());
  EXPECT_THROW(pipeline::gaussiansOnSurface(dir.file("run"), model, 0.f), sadsplat::Error);
  pcl::PointCloud<GaussianPoint> shorter = model;
  shorter.resize(model.size() - 1);
  EXPECT_THROW(pipeline::gaussiansOnSurface(dir.file("run"), shorter, 1.f), sadsplat::Error);
}

// The map's default footprint is what the training photos look at: Gaussians that a photo shows
// only near its image's edge (an oblique photo's far terrain) do not stretch the grid.
TEST(OrthoFootprint, IsWhatThePhotosShowInTheMiddleOfTheirImages) {
  // One photo 10 above the origin looking down (world (x, y, 0) -> u = 6 x + 32, v = 24 - 6 y;
  // 64 x 48 pixels): 100 Gaussians at |x|, |y| <= 1 (u 26-38, in the middle 80 % of the image,
  // columns 6-57) and 40 at x = -5 (u = 2: in the image, not in its middle).
  io::Scene scene;
  io::View v;
  v.name = "down.png";
  v.train = true;
  v.camera.width = 64;
  v.camera.height = 48;
  v.camera.fx = v.camera.fy = 60;
  v.camera.cx = 32;
  v.camera.cy = 24;
  v.camera.qvec = {0, 1, 0, 0};  // 180 degrees about x: the camera's z is the world's -z
  v.camera.tvec = {0, 0, 10};
  scene.views.push_back(v);
  pcl::PointCloud<GaussianPoint> cloud;
  const auto add = [&](float x, float y) {
    GaussianPoint p{};
    p.x = x, p.y = y, p.z = 0;
    p.opacity = 5;  // logit: 0.993
    for (float& s : p.scale) s = -3;
    p.rot[0] = 1;
    cloud.push_back(p);
  };
  for (int i = 0; i < 100; ++i) add(-1.f + 0.02f * i, -1.f + 0.02f * ((i * 37) % 100));
  for (int i = 0; i < 40; ++i) add(-5.f, -1.f + 0.05f * i);
  gaussians::TrainConfig config;
  gaussians::Trainer trainer(scene, config, gaussians::TrainerViews::kCamerasOnly);
  trainer.setGaussians(cloud);
  const pipeline::OrthoGrid grid = pipeline::footprintGrid(trainer, scene, 0.1);
  // x from -1 to 0.98 with a 2 % margin, y alike: ~21 cells a side (the edge's Gaussians would
  // make the grid ~63 cells wide).
  EXPECT_LE(grid.width, 23);
  EXPECT_GE(grid.width, 19);
  EXPECT_LE(grid.height, 23);
  EXPECT_GT(grid.x0, -1.2);
  // No photo shows any Gaussian in its middle: the footprint of all of them.
  pcl::PointCloud<GaussianPoint> edge_only;
  for (std::size_t i = 100; i < cloud.size(); ++i) {
    edge_only.push_back(cloud[i]);
    edge_only.back().x += 0.01f * static_cast<float>(i - 100);  // -5 .. -4.61
  }
  trainer.setGaussians(edge_only);
  const pipeline::OrthoGrid all = pipeline::footprintGrid(trainer, scene, 0.1);
  EXPECT_LT(all.x0, -4.9);
}

// eval reads the test views from the scene cache one at a time: the same scores as with the
// whole cache in memory.
TEST(StreamedViews, EvaluationReadsTheTestViewsOneAtATimeWithTheSameScores) {
  test::TempDir dir;
  const TrainConfig config = trainTinyRun(dir.file("run"));
  const io::Scene whole = io::readSceneCache(kCache);
  const io::Scene on_disk = io::readSceneCacheWithoutPixels(kCache);
  gaussians::Trainer trainer(whole, config);
  trainer.loadCheckpoint(dir.file("run/checkpoint.bin"));
  const eval::EvalResult a = eval::evaluate(trainer, whole, "");
  const eval::EvalResult b = eval::evaluate(trainer, on_disk, "");
  ASSERT_EQ(a.per_view.size(), b.per_view.size());
  ASSERT_GT(a.labelled_views, 0);
  EXPECT_EQ(a.labelled_views, b.labelled_views);
  for (std::size_t i = 0; i < a.per_view.size(); ++i) {
    EXPECT_EQ(a.per_view[i].psnr, b.per_view[i].psnr) << a.views[i];
    EXPECT_EQ(a.per_view[i].ssim, b.per_view[i].ssim) << a.views[i];
  }
  EXPECT_EQ(a.confusion.total(), b.confusion.total());
  EXPECT_EQ(a.confusion.overallAccuracy(), b.confusion.overallAccuracy());
  EXPECT_EQ(a.psnr_covered, b.psnr_covered);
}

TEST(StreamedViews, TrainLikeHeldViewsOnAGpu) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  expectStreamedViewsTrainLikeHeldViews("cuda");
}

// A view damaged inside a cache whose checksum is valid (a crafted file) is found by a loader
// thread when the streamed training first reads it: an error naming the cache and the image,
// raised in the training's thread, not a crash or a hang.
TEST(StreamedViews, ADamagedViewInTheCacheIsAClearError) {
  test::TempDir dir;
  io::writeSceneCache(dir.file("v3.cache"), io::readSceneCache(kCache));
  std::string bytes = test::readFile(dir.file("v3.cache"));
  // Every VIEW chunk: tag, size, name (u32 length + bytes), width, height, 11 doubles, roles,
  // has-labels, then the rgb block (u64 size + deflate stream), zeroed here.
  int damaged = 0;
  for (std::size_t at = bytes.find("VIEW"); at != std::string::npos;
       at = bytes.find("VIEW", at + 4)) {
    std::uint32_t name_length;
    std::memcpy(&name_length, &bytes[at + 12], 4);
    const std::size_t block = at + 4 + 8 + 4 + name_length + 8 + 11 * 8 + 2;
    std::uint64_t size;
    std::memcpy(&size, &bytes[block], 8);
    if (block + 8 + size > bytes.size()) continue;  // "VIEW" inside other bytes
    std::memset(&bytes[block + 8], 0, size);
    ++damaged;
  }
  ASSERT_GT(damaged, 0);
  const std::uint64_t sum = io::fnv1a64(bytes.data() + 32, bytes.size() - 32);
  std::memcpy(&bytes[24], &sum, 8);
  test::writeFile(dir.file("damaged.cache"), bytes);
  TrainConfig config;
  config.iterations = 10;
  config.stream_views = true;
  config.checkpoint_interval = 0;
  pipeline::TrainRunOptions o;
  o.scene = dir.file("damaged.cache");
  o.out = dir.file("run");
  try {
    pipeline::trainRun(o, config);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), dir.file("damaged.cache"));
    EXPECT_NE(std::string(e.what()).find("rgb"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sadsplat
