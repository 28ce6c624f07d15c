// The CLI: subcommands listed, info summaries, clear errors with non-zero exits, demo.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>

#include <nlohmann/json.hpp>

#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/io/train_log.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using test::kCli;
const std::string kScene = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene";

TEST(Cli, HelpListsTheSubcommands) {
  std::string out;
  EXPECT_EQ(test::runCommand(kCli + " --help", &out), 0);
  for (const char* sub : {"info", "import", "convert", "extract", "demo"}) {
    EXPECT_NE(out.find(sub), std::string::npos) << sub;
  }
}

TEST(Cli, InfoSummarisesAPly) {
  test::TempDir dir;
  io::writeGaussianPly(dir.file("m.ply"), test::randomGaussians(12, 51));
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " info " + dir.file("m.ply"), &out), 0) << out;
  EXPECT_NE(out.find("gaussians: 12"), std::string::npos) << out;
  EXPECT_NE(out.find("SH degree: 3"), std::string::npos) << out;
  EXPECT_NE(out.find("bounding box"), std::string::npos) << out;
}

TEST(Cli, BadInputGivesOneMessageAndNonZeroExit) {
  test::TempDir dir;
  test::writeFile(dir.file("bad.ply"), "not a ply");
  std::string out;
  EXPECT_EQ(test::runCommand(kCli + " info " + dir.file("bad.ply"), &out), 1);
  EXPECT_NE(out.find("bad.ply: magic: expected"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(kCli + " frobnicate", &out), 2);
  // A usage error is one line in sadsplat's form, like every other error.
  EXPECT_EQ(out.rfind("sadsplat: usage error: ", 0), 0u) << out;
  EXPECT_EQ(out.find('\n'), out.size() - 1) << out;
}

// The pseudo-label options reach the built-in backend (committed fixture cache: no OpenCV needed);
// a bad value is a usage error (exit 2), a bad combination an error naming the option (exit 1).
TEST(Cli, PseudoLabelOptionsReachTheBuiltinBackend) {
  test::TempDir dir;
  const std::string cache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
  const std::string run = kCli + " pseudo-labels " + cache + " --out " + dir.file("pl.cache");
  std::string out;
  ASSERT_EQ(test::runCommand(run + " --targets multiscale --scales 1,2 --fixed-region-size", &out),
            0)
      << out;
  EXPECT_NE(out.find("83 targets"), std::string::npos) << out;  // 67 with one 16-px SLIC layer
  EXPECT_NE(out.find("check on the labelled views"), std::string::npos) << out;
  // By default 16 px is the size at 800x450: 4 and 8 px on the 64x48 views (4 is the minimum).
  ASSERT_EQ(test::runCommand(run + " --targets multiscale --scales 1,2", &out), 0) << out;
  EXPECT_NE(out.find("1506 targets"), std::string::npos) << out;
  // Default: per class + cross-view check; report.json says what the run did.
  ASSERT_EQ(test::runCommand(run + " --report " + dir.file("rep"), &out), 0) << out;
  EXPECT_NE(out.find("per TOP1 class"), std::string::npos) << out;
  EXPECT_NE(out.find("grass: TOP1 >"), std::string::npos) << out;
  EXPECT_NE(out.find("cross-view check (agreement < 0.5) unkept:"), std::string::npos) << out;
  const std::string report = test::readFile(dir.file("rep/report.json"));
  EXPECT_NE(report.find("\"filter\": \"per-class\""), std::string::npos) << report;
  EXPECT_NE(report.find("\"min_view_agreement\": 0.5"), std::string::npos) << report;
  EXPECT_NE(report.find("\"filter_k\": 0.0"), std::string::npos) << report;
  EXPECT_NE(report.find("\"cross_view_unkept\""), std::string::npos) << report;
  EXPECT_NE(report.find("\"precision\""), std::string::npos) << report;
  ASSERT_EQ(test::runCommand(run + " --filter paper --min-view-agreement 0", &out), 0) << out;
  EXPECT_EQ(out.find("per TOP1 class"), std::string::npos) << out;
  EXPECT_EQ(out.find("cross-view check"), std::string::npos) << out;
  EXPECT_NE(out.find("(TOP1 > "), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(run + " --filter pooled", &out), 2) << out;
  EXPECT_EQ(test::runCommand(run + " --targets multiscale --scales 2,1", &out), 1) << out;
  EXPECT_NE(out.find("--scales"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(run + " --min-class-precision 1.5", &out), 2) << out;
  EXPECT_EQ(test::runCommand(run + " --min-view-agreement 1.5", &out), 2) << out;
  EXPECT_EQ(test::runCommand(run + " --targets foo", &out), 2) << out;
}

// `pick-views` names the photos to annotate; `synth --labelled auto` labels exactly those.
TEST(Cli, PickViewsNamesTheViewsSynthLabelsWithAuto) {
  test::TempDir dir;
  std::string out;
  const std::string synth = kCli +
                            " synth --kind port --seed 2 --capture grid-oblique --views 70 " +
                            "--width 96 --height 54 --points 3000 --cache " + dir.file("s.cache");
  ASSERT_EQ(test::runCommand(synth + " --labelled auto", &out), 0) << out;
  ASSERT_EQ(
      test::runCommand(
          kCli + " pick-views " + dir.file("s.cache") + " --json " + dir.file("pick.json"), &out),
      0)
      << out;
  EXPECT_NE(out.find("annotate these 3 photo(s)"), std::string::npos) << out;
  const nlohmann::json j = nlohmann::json::parse(test::readFile(dir.file("pick.json")));
  const io::Scene scene = io::readSceneCacheWithoutPixels(dir.file("s.cache"));
  std::vector<std::string> labelled;
  for (const io::View& v : scene.views)
    if (v.labelled) labelled.push_back(v.name);
  std::vector<std::string> picked;
  for (const auto& p : j.at("picked")) picked.push_back(p.at("name").get<std::string>());
  std::sort(picked.begin(), picked.end());
  EXPECT_EQ(picked, labelled);
  EXPECT_GT(j.at("picked").back().at("cumulative_share").get<double>(), 0.5);
  // Keeping those three, nothing is left to add much: the next view adds less than they saw.
  ASSERT_EQ(test::runCommand(kCli + " pick-views " + dir.file("s.cache") +
                                 " --keep-labelled --count 1 --json " + dir.file("more.json"),
                             &out),
            0)
      << out;
  const nlohmann::json more = nlohmann::json::parse(test::readFile(dir.file("more.json")));
  EXPECT_EQ(more.at("kept").size(), 3u);
  EXPECT_NEAR(more.at("kept_share").get<double>(),
              j.at("picked").back().at("cumulative_share").get<double>(), 1e-12);
  // With the default views (0, 7, 28: the mission's first nadir photos) ship and crane are never
  // annotated: pseudo-labels says so and points to pick-views.
  ASSERT_EQ(
      test::runCommand(kCli + " synth --kind port --seed 2 --capture grid-oblique --views 70 " +
                           "--width 96 --height 54 --points 3000 --cache " + dir.file("d.cache"),
                       &out),
      0)
      << out;
  // `info` says how much of the ground the annotated views see and which photo adds the most.
  ASSERT_EQ(test::runCommand(kCli + " info " + dir.file("d.cache"), &out), 0) << out;
  EXPECT_NE(out.find("annotated views see "), std::string::npos) << out;
  EXPECT_NE(out.find("the photo that adds the most: view_0"), std::string::npos) << out;
  ASSERT_EQ(test::runCommand(
                kCli + " pseudo-labels " + dir.file("d.cache") + " --out " + dir.file("d_pl.cache"),
                &out),
            0)
      << out;
  EXPECT_NE(out.find("warning: no annotated photo (3 labelled training views) shows ship, crane"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("pick-views"), std::string::npos) << out;
  // The views pick-views names show every class: no warning.
  ASSERT_EQ(test::runCommand(
                kCli + " pseudo-labels " + dir.file("s.cache") + " --out " + dir.file("s_pl.cache"),
                &out),
            0)
      << out;
  EXPECT_EQ(out.find("warning: no annotated photo"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(synth + " --labelled 0,x", &out), 1);
  EXPECT_NE(out.find("--labelled"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(kCli + " pick-views " + dir.file("none.cache"), &out), 1);
  EXPECT_NE(out.find("none.cache"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(kCli + " pick-views " + dir.file("s.cache") + " --count 0", &out), 1);
  EXPECT_NE(out.find("count"), std::string::npos) << out;
}

TEST(Cli, ImportInfoAndExtractWorkOnTheFixture) {
  if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  test::TempDir dir;
  std::string out;
  ASSERT_EQ(test::runCommand(
                kCli + " import " + kScene + " --scale 0.5 --out " + dir.file("s.cache"), &out),
            0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + " info " + dir.file("s.cache"), &out), 0) << out;
  EXPECT_NE(out.find("views: 8 (train 6, test 2, labelled 2)"), std::string::npos) << out;
  EXPECT_NE(out.find("image size: 32x24"), std::string::npos) << out;
  EXPECT_NE(out.find("2 building"), std::string::npos) << out;
  EXPECT_NE(out.find("annotated views see 100.0 % of the ground"), std::string::npos) << out;

  auto cloud = test::randomGaussians(40, 52, 3);
  io::writeGaussianPly(dir.file("m.ply"), cloud);
  ASSERT_EQ(
      test::runCommand(kCli + " extract " + dir.file("m.ply") + " --class building --classes " +
                           dir.file("s.cache") + " --out " + dir.file("b.ply"),
                       &out),
      0)
      << out;
  std::size_t buildings = 0;
  for (const auto& p : cloud) buildings += p.label == 2;
  EXPECT_EQ(io::readGaussianPly(dir.file("b.ply")).size(), buildings);
  EXPECT_EQ(test::runCommand(kCli + " extract " + dir.file("m.ply") + " --class water --classes " +
                                 dir.file("s.cache") + " --out " + dir.file("w.ply"),
                             &out),
            1);
  EXPECT_NE(out.find("one of: road, grass, building"), std::string::npos) << out;
}

TEST(Cli, TrainEvalAndResumeOnTheFixture) {
  if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  test::TempDir dir;
  std::string out;
  const std::string run = dir.file("run");
  ASSERT_EQ(
      test::runCommand(kCli + " train " + kScene + " --scale 1 --iterations 30 --out " + run, &out),
      0)
      << out;
  for (const char* f : {"model.ply", "config.json", "run.json", "checkpoint.bin"}) {
    EXPECT_FALSE(test::readFile(run + "/" + f).empty()) << f;
  }
  ASSERT_EQ(
      test::runCommand(
          kCli + " train " + kScene + " --scale 1 --iterations 40 --resume --out " + run, &out),
      0)
      << out;
  EXPECT_NE(out.find("[40/40]"), std::string::npos) << out;
  ASSERT_EQ(test::runCommand(kCli + " eval " + run, &out), 0) << out;
  for (const char* key :
       {"\"miou\"", "\"macc\"", "\"oacc\"", "\"per_class_iou\"", "\"psnr\"", "\"ssim\"",
        "\"num_gaussians\"", "\"iterations\": 40", "\"train_seconds\"", "\"device\""}) {
    EXPECT_NE(out.find(key), std::string::npos) << key;
  }
  EXPECT_FALSE(test::readFile(run + "/panels/view_002.png").empty());
  // Per-class extraction straight from the run directory (its model.ply and classes.json).
  ASSERT_EQ(test::runCommand(
                kCli + " extract " + run + " --class road --out " + dir.file("road.ply"), &out),
            0)
      << out;
  std::size_t roads = 0;
  for (const auto& p : io::readGaussianPly(run + "/model.ply")) roads += p.label == 0;
  EXPECT_EQ(io::readGaussianPly(dir.file("road.ply")).size(), roads);
  // --on-surface keeps the roads near the surface the views render: no more than all of them;
  // on a file (no views to render) it is an error.
  ASSERT_EQ(test::runCommand(kCli + " extract " + run + " --class road --on-surface 0.5 --out " +
                                 dir.file("road_on.ply"),
                             &out),
            0)
      << out;
  EXPECT_NE(out.find("on the surface (within 0.5): "), std::string::npos) << out;
  EXPECT_LE(io::readGaussianPly(dir.file("road_on.ply")).size(), roads);
  EXPECT_EQ(test::runCommand(kCli + " extract " + run +
                                 "/model.ply --class 0 --on-surface 1 --out " + dir.file("x.ply"),
                             &out),
            1);
  EXPECT_NE(out.find("--on-surface: expected a run directory"), std::string::npos) << out;
  // sadsplat reads every cloud it writes: info, convert and extract take each of them.
  const std::string n = std::to_string(io::readGaussianPly(run + "/model.ply").size());
  for (const char* f : {"model.ply", "model.pcd", "model_semantic.pcd", "model_semantic.ply"}) {
    ASSERT_EQ(test::runCommand(kCli + " info " + run + "/" + f, &out), 0) << f << out;
    EXPECT_NE(out.find(": " + n + "\n"), std::string::npos) << f << out;
  }
  ASSERT_EQ(
      test::runCommand(
          kCli + " convert " + run + "/model_semantic.pcd " + dir.file("conv/semantic.ply"), &out),
      0)
      << out;
  EXPECT_EQ(io::readSemanticCloud(dir.file("conv/semantic.ply")).size(),
            io::readSemanticCloud(run + "/model_semantic.ply").size());
  ASSERT_EQ(
      test::runCommand(kCli + " convert " + run + "/model.pcd " + dir.file("conv/m.ply"), &out), 0)
      << out;
  EXPECT_EQ(io::readGaussianPly(dir.file("conv/m.ply")).size(),
            io::readGaussians(run + "/model.pcd").size());
  ASSERT_EQ(
      test::runCommand(kCli + " extract " + run + "/model_semantic.pcd --class road --classes " +
                           run + "/classes.json --out " + dir.file("road_sem.pcd"),
                       &out),
      0)
      << out;
  EXPECT_EQ(io::readSemanticCloud(dir.file("road_sem.pcd")).size(), roads);
  // A value outside an option's choices is a usage error (exit 2) naming the flag.
  EXPECT_EQ(test::runCommand(
                kCli + " train " + kScene + " --out " + dir.file("r2") + " --device tpu", &out),
            2);
  EXPECT_NE(out.find("--device"), std::string::npos) << out;
  // The same value in a --config file is an error naming the file and the key (exit 1).
  test::writeFile(dir.file("tpu.json"), "{\"device\": \"tpu\"}");
  EXPECT_EQ(test::runCommand(kCli + " train " + kScene + " --out " + dir.file("r3") + " --config " +
                                 dir.file("tpu.json"),
                             &out),
            1);
  EXPECT_NE(out.find("device: expected cpu,cuda, got tpu"), std::string::npos) << out;
}

// --schedule long: the run's config has the long schedule's keys (prune after the densification,
// refine the last sixth), keys the user set stay; other schedule names are usage errors.
TEST(Cli, CompactTilesAndGlbOfATrainedRun) {
  if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  test::TempDir dir;
  std::string out;
  const std::string run = dir.file("run");
  ASSERT_EQ(
      test::runCommand(kCli + " train " + kScene + " --scale 1 --iterations 30 --out " + run, &out),
      0)
      << out;
  const std::size_t n = io::readGaussianPly(run + "/model.ply").size();
  ASSERT_GT(n, 20u);
  // compact: a run directory with half the Gaussians that eval scores.
  ASSERT_EQ(
      test::runCommand(
          kCli + " compact " + run + " --ratio 0.5 --refine 3 --out " + dir.file("half"), &out),
      0)
      << out;
  EXPECT_NE(out.find("refined 3 iterations"), std::string::npos) << out;
  EXPECT_EQ(io::readGaussianPly(dir.file("half") + "/model.ply").size(), (n + 1) / 2);
  ASSERT_EQ(test::runCommand(kCli + " eval " + dir.file("half"), &out), 0) << out;
  EXPECT_NE(out.find("\"num_gaussians\": " + std::to_string((n + 1) / 2)), std::string::npos)
      << out;
  EXPECT_NE(out.find("\"iterations\": 33"), std::string::npos) << out;  // 30 trained + 3 refined
  // Exactly one of --count / --ratio / --model.
  EXPECT_EQ(test::runCommand(
                kCli + " compact " + run + " --ratio 0.5 --count 3 --out " + dir.file("bad"), &out),
            1);
  EXPECT_NE(out.find("exactly one"), std::string::npos) << out;
  // tiles: every Gaussian in one leaf; a local tileset (the fixture has no georeference).
  ASSERT_EQ(test::runCommand(kCli + " tiles " + run + " --out " + dir.file("tiles") +
                                 " --max-splats " + std::to_string(n / 3),
                             &out),
            0)
      << out;
  EXPECT_NE(out.find("local tileset"), std::string::npos) << out;
  const nlohmann::json t = nlohmann::json::parse(test::readFile(dir.file("tiles/tileset.json")));
  EXPECT_EQ(t["extras"]["georeferenced"], false);
  EXPECT_FALSE(t["root"].contains("transform"));
  std::size_t leaf_splats = 0;
  std::function<void(const nlohmann::json&)> walk = [&](const nlohmann::json& tile) {
    const std::string glb = dir.file("tiles/" + tile["content"]["uri"].get<std::string>());
    ASSERT_EQ(test::runCommand(kCli + " info " + glb, &out), 0) << out;
    if (!tile.contains("children")) {
      const auto at = out.find("gaussians: ");
      ASSERT_NE(at, std::string::npos) << out;
      leaf_splats += std::stoul(out.substr(at + 11));
    }
    for (const auto& c : tile.value("children", nlohmann::json::array())) walk(c);
  };
  walk(t["root"]);
  EXPECT_EQ(leaf_splats, n);
  // convert to .glb, and an unknown frame is said, not guessed silently.
  ASSERT_EQ(test::runCommand(kCli + " convert " + run + " " + dir.file("m.glb"), &out), 0) << out;
  EXPECT_NE(out.find("glTF axes"), std::string::npos) << out;
  ASSERT_EQ(test::runCommand(kCli + " info " + dir.file("m.glb"), &out), 0) << out;
  EXPECT_NE(out.find("gaussians: " + std::to_string(n)), std::string::npos) << out;
}

TEST(Cli, TheLongScheduleSetsItsKeysAndKeepsGivenOnes) {
  test::TempDir dir;
  const std::string cache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
  const std::string run = dir.file("run");
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " train " + cache + " --schedule long --iterations 24 " +
                                 "--drop full --out " + run,
                             &out),
            0)
      << out;
  EXPECT_NE(out.find("long schedule: densify_until -1 -> 6; lambda_l0_from 0 -> 6; "
                     "recovery_iterations 0 -> 4;"),
            std::string::npos)
      << out;
  const std::string config = io::readWholeFile(run + "/config.json");
  EXPECT_NE(config.find("\"densify_until\": 6"), std::string::npos) << config;
  EXPECT_NE(config.find("\"lambda_l0_from\": 6"), std::string::npos) << config;
  EXPECT_NE(config.find("\"recovery_iterations\": 4"), std::string::npos) << config;
  EXPECT_NE(config.find("\"iterations\": 24"), std::string::npos) << config;
  EXPECT_EQ(
      test::runCommand(kCli + " train " + cache + " --schedule short --out " + dir.file("x"), &out),
      2)
      << out;
}

// A model that densification grows to max_gaussians is said once, with the cap and what to change;
// a run that stays below it says nothing of the kind.
TEST(Cli, TrainSaysOnceWhenTheModelReachesTheGaussianCap) {
  test::TempDir dir;
  const std::string cache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
  // Every Gaussian densifies (threshold 0) every 5 iterations (the 20-iteration schedule densifies
  // from iteration 2): 400 -> 800 at 5.
  const std::string config = dir.file("grow.json");
  test::writeFile(config,
                  R"({"densify_grad_threshold": 0, "densify_interval": 5, "max_gaussians": 600})");
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " train " + cache + " --iterations 20 --config " + config +
                                 " --out " + dir.file("capped"),
                             &out),
            0)
      << out;
  const std::string said = "[densify] iteration 5: the model reached max_gaussians (600)";
  const std::size_t at = out.find(said);
  ASSERT_NE(at, std::string::npos) << out;
  EXPECT_EQ(out.find("[densify]", at + 1), std::string::npos) << out;
  EXPECT_NE(out.find("raise densify_grad_threshold"), std::string::npos) << out;
  // The log says it too, once, for readers of the run that did not see the terminal.
  int cap_records = 0;
  for (const io::TrainLogRecord& r : io::readTrainLog(dir.file("capped") + "/train_log.jsonl")) {
    if (r.type != "max_gaussians_reached") continue;
    ++cap_records;
    EXPECT_EQ(r.iteration, 5);
    EXPECT_GE(r.gaussians, 600);
  }
  EXPECT_EQ(cap_records, 1);

  ASSERT_EQ(test::runCommand(
                kCli + " train " + cache + " --iterations 20 --out " + dir.file("uncapped"), &out),
            0)
      << out;
  EXPECT_EQ(out.find("[densify]"), std::string::npos) << out;
}

// A run trained on a relative scene path is evaluated from another working directory (run.json
// keeps the scene's absolute path), and eval's metrics count the floaters.
// A scene without classes.json and label maps (photos + COLMAP only): plain 3DGS end to end.
TEST(Cli, AnRgbOnlySceneTrainsEvaluatesAndSaysWhyThereIsNoMiou) {
  if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  test::TempDir dir;
  const std::string scene = test::copyTree(kScene, dir.file("scene"));
  std::remove((scene + "/classes.json").c_str());
  std::remove((scene + "/split.json").c_str());
  ASSERT_EQ(std::system(("rm -rf '" + scene + "/labels'").c_str()), 0);
  std::string out;
  const std::string run = dir.file("run");
  ASSERT_EQ(test::runCommand(kCli + " train " + scene + " --iterations 30 --out " + run, &out), 0)
      << out;
  // The import scale and the short run's schedule are said.
  EXPECT_NE(out.find("at image scale 0.5"), std::string::npos) << out;
  EXPECT_NE(out.find("schedule of a run of 30 iterations"), std::string::npos) << out;
  EXPECT_NE(out.find("schedule: 30 iterations; no densification; opacity reset none"),
            std::string::npos)
      << out;
  io::PlyFileInfo info;
  io::readGaussianPly(run + "/model.ply", &info);
  EXPECT_EQ(info.feature_dim, 0);
  EXPECT_FALSE(io::pathExists(run + "/model_semantic.ply"));
  ASSERT_EQ(test::runCommand(kCli + " eval " + run, &out), 0) << out;
  EXPECT_NE(out.find("\"miou\": null"), std::string::npos) << out;
  EXPECT_NE(out.find("no classes"), std::string::npos) << out;
  EXPECT_NE(out.find("\"psnr\""), std::string::npos) << out;
  ASSERT_EQ(test::runCommand(kCli + " info " + run, &out), 0) << out;
  EXPECT_NE(out.find("run directory"), std::string::npos) << out;
  EXPECT_NE(out.find("georeference: none"), std::string::npos) << out;
  EXPECT_EQ(
      test::runCommand(kCli + " extract " + run + " --class road --out " + dir.file("r.pcd"), &out),
      1);
  EXPECT_NE(out.find("no classes to extract"), std::string::npos) << out;
  // Maps of a plain 3DGS model: RGB and depth, no class images, a LAS of code 0.
  if (test::runCommand("gdalinfo --version") != 0) return;  // built or installed without GDAL
  ASSERT_EQ(test::runCommand(kCli + " render " + run + " --views all --out " + dir.file("r"), &out),
            0)
      << out;
  EXPECT_NE(out.find("no classes"), std::string::npos) << out;
  EXPECT_TRUE(io::pathExists(dir.file("r/rgb")));
  EXPECT_FALSE(io::pathExists(dir.file("r/class")));
  ASSERT_EQ(test::runCommand(kCli + " ortho " + run + " --gsd 0.2 --out " + dir.file("o"), &out), 0)
      << out;
  EXPECT_TRUE(io::pathExists(dir.file("o/orthophoto.tif")));
  EXPECT_FALSE(io::pathExists(dir.file("o/classes.tif")));
  ASSERT_EQ(test::runCommand(kCli + " convert " + run + "/model.ply " + dir.file("m.las"), &out), 0)
      << out;
  EXPECT_NE(out.find(" 0 (created, never classified)"), std::string::npos) << out;
}

TEST(Cli, EvalFindsTheSceneOfARunFromAnyDirectory) {
  test::TempDir dir;
  std::string out;
  const std::string cache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
  ASSERT_EQ(test::runCommand("cd " + dir.path() + " && cp " + cache + " scene.cache && " + kCli +
                                 " train scene.cache --iterations 5 --out run",
                             &out),
            0)
      << out;
  ASSERT_EQ(test::runCommand("cd / && " + kCli + " eval " + dir.file("run"), &out), 0) << out;
  for (const char* key : {"\"floaters\"", "\"scene_extent\"", "\"larger_than_10pct_extent\"",
                          "\"seen_by_under_2_training_views\""}) {
    EXPECT_NE(out.find(key), std::string::npos) << key << out;
  }
}

// The demo end to end, shortened: pseudo-labels are written and used, the drop acts, the run is
// evaluated; --baseline skips both.
TEST(Cli, DemoRunsTheMethodAndTheBaseline) {
  if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  test::TempDir dir;
  std::string out;
  // The README's first run: from a directory without out/, into a nested path that does not exist.
  ASSERT_EQ(
      test::runCommand(
          "cd " + dir.path() + " && " + kCli + " demo --iterations 20 --out out/nested/full", &out),
      0)
      << out;
  ASSERT_EQ(std::rename(dir.file("out/nested/full").c_str(), dir.file("full").c_str()), 0);
  EXPECT_NE(out.find("60 pseudo-labelled views"), std::string::npos) << out;
  EXPECT_NE(out.find("[drop] iteration 5: removed"), std::string::npos) << out;
  EXPECT_NE(out.find("| mIoU |"), std::string::npos) << out;
  EXPECT_TRUE(io::pathExists(dir.file("full/pseudo_labels/report.json")));
  EXPECT_TRUE(io::pathExists(dir.file("full/run/model.ply")));
  // The held-out views sit between training views: most of their pixels are covered.
  const auto metrics = nlohmann::json::parse(test::readFile(dir.file("full/run/metrics.json")));
  EXPECT_TRUE(metrics["psnr_covered"].is_number()) << metrics.dump();
  EXPECT_GT(metrics["covered_fraction"].get<double>(), 0.5);
  EXPECT_LE(metrics["covered_fraction"].get<double>(), 1.0);
  EXPECT_EQ(metrics["covered_min_views"].get<int>(), 2);

  ASSERT_EQ(
      test::runCommand(kCli + " demo --baseline --iterations 10 --out " + dir.file("base"), &out),
      0)
      << out;
  EXPECT_NE(out.find("pseudo-labels: skipped (--baseline)"), std::string::npos) << out;
  EXPECT_EQ(out.find("[drop]"), std::string::npos) << out;
  EXPECT_FALSE(io::pathExists(dir.file("base/pseudo_labels")));
  EXPECT_TRUE(io::pathExists(dir.file("base/run/metrics.json")));
}

}  // namespace
}  // namespace sadsplat
