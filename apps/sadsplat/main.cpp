// The sadsplat command line: parses arguments, calls the library, prints. Errors of type
// sadsplat::Error become one message on stderr and exit status 1 (2 for usage errors).
#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstring>
#include <iostream>
#include <optional>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/distributed/rank_group.h"
#include "sadsplat/eval/experiment_table.h"
#include "sadsplat/gaussians/cpu_threads.h"
#include "sadsplat/gaussians/gaussian_tensors.h"
#include "sadsplat/gaussians/initialization.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/file_info.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/io/splat_formats.h"
#include "sadsplat/pipeline/pseudo_label_run.h"
#include "sadsplat/pipeline/runs.h"
#include "sadsplat/semantic_drop/class_extraction.h"
#include "sadsplat/synth/aerial_benchmark.h"
#if SADSPLAT_HAVE_OPENCV
#include "sadsplat/synth/scene_writer.h"
#endif
#if SADSPLAT_HAVE_VIZ
#include <unistd.h>

#include <cstdlib>

#include "sadsplat/viz/display.h"
#include "sadsplat/viz/experiment_charts.h"
#include "sadsplat/viz/splat_view.h"
#include "sadsplat/viz/training_report.h"
#endif

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// `extract`: the points of one class (or of all others) of a Gaussian or a semantic cloud,
// read and written with the given functions.
template <typename PointT, typename Read, typename Write>
void extractClass(const std::string& in, const std::string& out, std::uint32_t class_id,
                  bool negative, Read read, Write write) {
  const auto cloud = std::make_shared<pcl::PointCloud<PointT>>(read(in));
  sadsplat::semantic_drop::ClassExtraction<PointT> filter;
  filter.setClassId(class_id);
  filter.setNegative(negative);
  filter.setInputCloud(cloud);
  pcl::PointCloud<PointT> kept;
  filter.filter(kept);
  write(out, kept);
  std::cout << "kept " << kept.size() << " of " << cloud->size() << " points\n";
}

struct SynthArgs {
  std::string kind = "city";
  std::uint64_t seed = 0;
  std::string preset;
  int views = -1, width = -1, height = -1, points = -1;
  std::vector<int> labelled;
  std::string out;
  std::string cache;
  bool preview = false;
  bool colmap_binary = false;
};

int runSynth(const SynthArgs& a) {
  using namespace sadsplat;
  const synth::SceneKind kind = synth::parseSceneKind(a.kind);
  synth::SynthOptions o;
  if (a.preset == "demo") {
    o = synth::SynthOptions::demo(kind, a.seed);
  } else if (a.preset.empty() || a.preset == "full") {
    o.kind = kind;
    o.seed = a.seed;
  } else if (a.preset == "city-xl") {
    if (kind != synth::SceneKind::kCity) {
      throw Error("<command line>", "--preset city-xl", "--kind city", a.kind);
    }
    o = synth::SynthOptions::cityXl(a.seed);
  } else {
    throw Error("<command line>", "--preset", "demo, full or city-xl", a.preset);
  }
  if (a.views > 0) o.views = a.views;
  if (a.width > 0) o.width = a.width;
  if (a.height > 0) o.height = a.height;
  if (a.points > 0) o.max_points = a.points;
  if (!a.labelled.empty()) o.labelled = a.labelled;
  std::cout << "generating " << a.kind << " seed " << a.seed << ": " << o.views << " views of "
            << o.width << "x" << o.height << " ..." << std::flush;
  const synth::SynthScene scene = synth::generate(o);
  std::cout << " " << scene.seconds << " s, " << scene.points.size() << " sparse points\n";
  if (!a.cache.empty()) io::writeSceneCache(a.cache, synth::toScene(scene));
  if (!a.out.empty()) {
#if SADSPLAT_HAVE_OPENCV
    synth::writeScene(scene, a.out,
                      a.colmap_binary ? synth::ColmapFormat::kBinary : synth::ColmapFormat::kText);
    if (a.preview) synth::writeContactSheet(scene, a.out + "/preview.png");
#else
    throw Error(a.out, "--out", "a sadsplat build with OpenCV to write PNG scene directories",
                "a build without it (use --cache)");
#endif
  }
  const synth::SynthStats stats = synth::computeStats(scene);
  std::cout << "effective pixels: " << 100.0 * stats.effective_share << " %\nclass shares:";
  for (std::size_t c = 0; c < scene.classes.size(); ++c) {
    std::cout << " " << scene.classes[c].name << " " << 100.0 * stats.class_share[c] << "%";
  }
  std::cout << "\nwrote " << (a.out.empty() ? a.cache : a.out) << "\n";
  return 0;
}

#if SADSPLAT_HAVE_VIZ
// VTK renders through X only here. An offscreen job (a screenshot, a report) on a machine with
// no display runs itself again under xvfb-run when that is installed, so that it simply works.
void rerunUnderXvfbIfHeadless(int argc, char** argv) {
  if (sadsplat::viz::haveDisplay() || std::getenv("SADSPLAT_UNDER_XVFB") != nullptr) return;
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0) return;  // requireDisplay says why
  setenv("SADSPLAT_UNDER_XVFB", "1", 1);
  std::vector<char*> args = {const_cast<char*>("xvfb-run"), const_cast<char*>("-a"),
                             const_cast<char*>("-s"),
                             const_cast<char*>("-screen 0 3840x2160x24 -nolisten tcp")};
  for (int i = 0; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execvp("xvfb-run", args.data());  // returns only on failure: then the display error follows
}

// "1280x720" -> width, height.
void parseSize(const std::string& text, int* width, int* height) {
  const auto x = text.find('x');
  try {
    std::size_t used_w = 0, used_h = 0;
    if (x == std::string::npos) throw std::invalid_argument("no x");
    *width = std::stoi(text.substr(0, x), &used_w);
    *height = std::stoi(text.substr(x + 1), &used_h);
    if (used_w != x || used_h != text.size() - x - 1) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw sadsplat::Error("<command line>", "--size", "WIDTHxHEIGHT, e.g. 1280x720", text);
  }
}
#endif

// SIGINT / SIGTERM during training: stop after the current iteration with a checkpoint.
std::atomic<bool> g_stop{false};
extern "C" void requestStop(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sadsplat " SADSPLAT_VERSION
               ": compact semantic 3D Gaussian Splatting for aerial scenes, as PCL clouds"};
  app.require_subcommand(1);

  auto* info = app.add_subcommand("info", "Summarise a PLY, PCD, scene directory or scene cache");
  std::string info_path;
  info->add_option("FILE", info_path, "file or scene directory")->required();

  auto* import = app.add_subcommand("import", "Import a scene directory into a scene cache");
  std::string import_dir, import_out;
  sadsplat::io::ImportOptions import_options;
  import->add_option("SCENE", import_dir, "scene directory")->required();
  import->add_option("--out", import_out, "scene cache file to write")->required();
  import->add_option("--scale", import_options.scale, "image scale in (0, 1]")
      ->capture_default_str();
  import->add_option("--max-width", import_options.max_width, "cap on image width (0 = none)");

  auto* convert = app.add_subcommand(
      "convert",
      "Convert a cloud: Gaussians .ply/.pcd/.splat/.spz (also read: .sog, .compressed.ply), "
      "semantic clouds .ply/.pcd");
  std::string convert_in, convert_out;
  convert->add_option("IN", convert_in, "input .ply, .pcd, .splat, .spz, .sog or .compressed.ply")
      ->required();
  convert->add_option("OUT", convert_out, "output .ply, .pcd, .splat or .spz")->required();
  int convert_spz_version = 3;
  convert
      ->add_option("--spz-version", convert_spz_version,
                   ".spz: 3 (gzip, every SPZ reader), 4 (zstd, the current version) or 2 (what "
                   "older web viewers read)")
      ->check(CLI::IsMember({2, 3, 4}))
      ->capture_default_str();

  auto* extract = app.add_subcommand("extract", "Write the Gaussians of one class");
  std::string extract_in, extract_out, extract_class, extract_classes;
  bool extract_negative = false;
  extract->add_option("MODEL", extract_in, "input .ply / .pcd, or a run directory")->required();
  extract->add_option("--class", extract_class, "class name (or id)")->required();
  extract->add_option("--classes", extract_classes, "classes.json or scene cache naming classes");
  extract->add_option("--out", extract_out, "output .ply or .pcd")->required();
  extract->add_flag("--negative", extract_negative, "keep every class except this one");

  auto* train = app.add_subcommand("train", "Train semantic Gaussians on a scene");
  std::string train_scene, train_out, train_config_file, train_device;
  int train_iterations = -1;
  long long train_seed = -1;
  double train_scale = 0.5;
  bool train_resume = false;
  bool train_profile = false;
  int train_nproc = 0;
  int train_views_per_step = 0;
  bool train_batch_schedule = false;
  bool train_prune_floaters = false;
  train->add_option("SCENE", train_scene, "scene directory or scene cache")->required();
  train->add_option("--out", train_out, "run directory")->required();
  train->add_option("--config", train_config_file, "JSON file with TrainConfig keys");
  train->add_option("--iterations", train_iterations, "iterations (paper: 7000)");
  train->add_option("--device", train_device, "cpu or cuda");
  train->add_option("--seed", train_seed, "random seed (42)");
  train->add_option("--scale", train_scale, "image scale when importing a directory")
      ->capture_default_str();
  train->add_flag("--resume", train_resume, "continue from RUN/checkpoint.bin");
  train
      ->add_option(
          "--nproc", train_nproc,
          "data-parallel ranks on this machine (c10d Gloo on CPUs, NCCL with --device cuda: "
          "one GPU each); or start the ranks with torchrun --no-python, which sets RANK / "
          "WORLD_SIZE / LOCAL_RANK / MASTER_ADDR / MASTER_PORT. 1: a group of one rank")
      ->check(CLI::Range(1, 256));
  train
      ->add_option("--views-per-step", train_views_per_step,
                   "training views per step and rank (1); the loss is their mean")
      ->check(CLI::Range(1, 1024));
  train->add_flag("--batch-schedule", train_batch_schedule,
                  "with a global batch of B = ranks x views per step > 1, take the schedule in B "
                  "times fewer steps (iterations, densification, resets, drop) and the learning "
                  "rates x sqrt(B): as many views seen as one view per step");
  train->add_flag("--prune-floaters", train_prune_floaters,
                  "after the last iteration remove Gaussians seen by fewer than 2 training views "
                  "or larger than 0.1 x the scene extent (config: floater_min_views, "
                  "floater_max_scale)");
  train->add_flag("--profile", train_profile,
                  "time each phase of the iterations (waits for the GPU at every phase "
                  "boundary) and write RUN/profile.md");
  std::string train_drop;
  double train_p_base = -1;
  train->add_option("--drop", train_drop, "semantic-aware drop: none, semantic, structure or full");
  train->add_option("--p-base", train_p_base, "base drop rate P_base (1.0)");
  double train_lambda_l0 = -1;
  train->add_option(
      "--lambda-l0", train_lambda_l0,
      "weight of the L0 sparsity loss (0.2; 0.1 renders 1.0-1.4 dB better and keeps ~1.7x more)");
  int train_l0_from = -1, train_l0_ramp = -1;
  train
      ->add_option("--lambda-l0-from", train_l0_from,
                   "the L0 loss starts at this iteration (not the paper; 0 = from the start)")
      ->check(CLI::NonNegativeNumber);
  train
      ->add_option("--lambda-l0-ramp", train_l0_ramp,
                   "the L0 weight rises linearly over this many iterations (0 = at once)")
      ->check(CLI::NonNegativeNumber);
  double train_l0_importance = -1;
  train
      ->add_option("--l0-importance", train_l0_importance,
                   "weight the L0 loss towards the Gaussians that contribute least to the "
                   "training views, exponent gamma (not the paper; 0 = the plain mean)")
      ->check(CLI::NonNegativeNumber);
  int train_recovery = -1;
  train
      ->add_option("--recovery", train_recovery,
                   "the last N iterations train without gates, L0 and drops, the gates folded "
                   "into the opacities (not the paper; 0 = the paper's schedule)")
      ->check(CLI::NonNegativeNumber);
  double train_recovery_prune = -1;
  train
      ->add_option("--recovery-prune", train_recovery_prune,
                   "at the start of the recovery also remove this share of the Gaussians that "
                   "contribute least to the training views (0 = none)")
      ->check(CLI::Range(0.0, 0.999));

  auto* pseudo = app.add_subcommand("pseudo-labels",
                                    "Write confidence maps and filtered pseudo-labels of the "
                                    "training views into the scene cache");
  sadsplat::pipeline::PseudoLabelRunOptions pseudo_options;
  pseudo
      ->add_option("SCENE", pseudo_options.scene,
                   "scene cache (updated in place) or scene directory")
      ->required();
  pseudo->add_option("--out", pseudo_options.out, "scene cache to write instead");
  pseudo->add_option("--backend", pseudo_options.backend, "builtin or torchscript")
      ->capture_default_str();
  pseudo->add_option("--sam", pseudo_options.sam_model, "torchscript: SAM TorchScript file");
  pseudo->add_option("--clip", pseudo_options.clip_model, "torchscript: CLIP TorchScript file");
  pseudo->add_option("--report", pseudo_options.report_dir,
                     "write report.json/.txt and overlays here");
  pseudo
      ->add_option("--filter-k", pseudo_options.filter.filter_k,
                   "thresholds mean + k std (paper: 1; 0 keeps ~3x more at about the same "
                   "precision and trained better)")
      ->capture_default_str();
  std::string pseudo_filter = "per-class";
  pseudo
      ->add_option("--filter", pseudo_filter,
                   "per-class: mean + k std over the targets of each TOP1 class (class-balanced); "
                   "paper: over all targets (the paper's filter; with --filter-k 1 "
                   "--min-view-agreement 0 exactly the paper)")
      ->check(CLI::IsMember({"per-class", "paper"}))
      ->capture_default_str();
  pseudo
      ->add_option(
          "--min-class-precision", pseudo_options.filter.min_class_precision,
          "remove the pseudo-labels of a class whose kept labels agree with the labelled "
          "views' ground truth on fewer than this share of pixels (0 = off; not the paper)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  pseudo
      ->add_option("--min-view-agreement", pseudo_options.filter.min_view_agreement,
                   "unkeep a target when the other views seeing its sparse points vote for its "
                   "class less often than this (0 = off; not the paper)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  pseudo
      ->add_option("--region-size", pseudo_options.builtin.superpixels.region_size,
                   "builtin: superpixel size in pixels of an 800x450 view (scaled with the view's "
                   "size, at least 4; see --fixed-region-size)")
      ->capture_default_str();
  bool pseudo_fixed_region_size = false;
  pseudo->add_flag("--fixed-region-size", pseudo_fixed_region_size,
                   "builtin: --region-size in pixels whatever the view's size");
  std::string pseudo_scale = "log-odds";
  pseudo
      ->add_option("--filter-scale", pseudo_scale,
                   "TOP1/dTOP measured on the scores (paper) or as log-odds")
      ->check(CLI::IsMember({"score", "log-odds"}))
      ->capture_default_str();
  std::string pseudo_targets = "slic";
  pseudo
      ->add_option("--targets", pseudo_targets,
                   "builtin: mask generator, slic (equal-size superpixels), graph, or multiscale "
                   "(overlapping SLIC layers of sizes region-size x --scales)")
      ->check(CLI::IsMember({"slic", "graph", "multiscale"}))
      ->capture_default_str();
  pseudo
      ->add_option("--scales", pseudo_options.builtin.multiscale,
                   "builtin, multiscale: ascending region-size factors")
      ->delimiter(',')
      ->capture_default_str();
  pseudo
      ->add_option("--graph-k", pseudo_options.builtin.graph.k,
                   "builtin, graph: merge threshold scale k")
      ->capture_default_str();
  pseudo
      ->add_option("--graph-min-size", pseudo_options.builtin.graph.min_size,
                   "builtin, graph: smallest target in pixels")
      ->capture_default_str();
  bool pseudo_no_geometry = false;
  pseudo->add_flag("--no-geometry", pseudo_no_geometry,
                   "builtin: do not use the sparse points' heights");
  pseudo->add_option("--scale", pseudo_options.scale, "image scale when importing a directory")
      ->capture_default_str();

  auto* evaluate = app.add_subcommand("eval", "Evaluate a training run on its test views");
  std::string eval_run, eval_scene;
  evaluate->add_option("RUN", eval_run, "run directory")->required();
  evaluate->add_option("--scene", eval_scene, "scene to evaluate on (default: the run's)");

  auto* table = app.add_subcommand(
      "table",
      "Tables of an experiment folder: RESULTS/<kind>_<seed>/<config>_t<seed>/metrics.json");
  std::string table_results, table_baseline = "none", table_out;
  table->add_option("RESULTS", table_results, "experiment results folder")->required();
  table->add_option("--baseline", table_baseline, "configuration to compare the counts with")
      ->capture_default_str();
  table->add_option("--out", table_out, "also write the Markdown to this file");
  std::string table_plots;
  table->add_option("--plots", table_plots,
                    "write the frontier charts (frontier_psnr.png, frontier_miou.png) here (VTK)");
  double table_goal_fewer = 12, table_goal_psnr = 0.3;
  table
      ->add_option("--goal-fewer", table_goal_fewer,
                   "charts: the target's times fewer Gaussians (0: no target drawn)")
      ->capture_default_str();
  table
      ->add_option("--goal-psnr-loss", table_goal_psnr,
                   "charts: the target's largest PSNR loss in dB")
      ->capture_default_str();

  auto* demo = app.add_subcommand("demo",
                                  "Generate the demo city, pseudo-label it, train on CPU with the "
                                  "semantic-aware drop, evaluate");
  std::string demo_out = "out/demo";
  int demo_iterations = 600;
  demo->add_option("--out", demo_out, "output directory")->capture_default_str();
  demo->add_option("--iterations", demo_iterations, "training iterations")->capture_default_str();
  bool demo_baseline = false;
  demo->add_flag("--baseline", demo_baseline, "no pseudo-labels and no drop (the paper's Net-1)");

  auto* synth_cmd = app.add_subcommand("synth", "Generate a procedural aerial benchmark scene");
  SynthArgs synth_args;
  synth_cmd->add_option("--kind", synth_args.kind, "city, country or port")->capture_default_str();
  synth_cmd->add_option("--seed", synth_args.seed, "scene seed")->capture_default_str();
  synth_cmd->add_option("--preset", synth_args.preset,
                        "demo (320x180), full (1600x900) or city-xl (a city of 4x the area, "
                        "280 views of 1600x900)");
  synth_cmd->add_option("--views", synth_args.views, "number of views (70)");
  synth_cmd->add_option("--width", synth_args.width, "image width (1600)");
  synth_cmd->add_option("--height", synth_args.height, "image height (900)");
  synth_cmd->add_option("--points", synth_args.points, "sparse points to keep");
  synth_cmd->add_option("--labelled", synth_args.labelled, "labelled views (0,7,28)")
      ->delimiter(',');
  synth_cmd->add_option("--out", synth_args.out, "scene directory to write (PNG, needs OpenCV)");
  synth_cmd->add_option("--cache", synth_args.cache, "scene cache file to write");
  synth_cmd->add_flag("--preview", synth_args.preview, "also write OUT/preview.png");
  synth_cmd->add_flag("--colmap-binary", synth_args.colmap_binary,
                      "with --out: write sparse/0 as a binary COLMAP model (cameras.bin, ...)");

#if SADSPLAT_HAVE_VIZ
  auto* view = app.add_subcommand(
      "view", "Look at a model in 3D (VTK): splats by class, colour, confidence, gate or opacity");
  std::string view_model, view_compare, view_color = "class", view_classes, view_size = "1280x720";
  sadsplat::viz::SplatViewOptions view_options;
  view->add_option("MODEL", view_model, "run directory, or a .ply / .pcd cloud")->required();
  view->add_option("--color", view_color, "class, rgb, confidence, gate or opacity")
      ->capture_default_str();
  view->add_option("--class", view_classes,
                   "show only these classes (names or ids, comma-separated)");
  view->add_option("--view", view_options.view,
                   "start at this camera of the run's scene (e.g. view_042)");
  view->add_option("--compare", view_compare, "a second model beside it, cameras linked");
  view->add_option("--screenshot", view_options.screenshot, "write this PNG (offscreen) and exit");
  view->add_option("--size", view_size, "window / screenshot size")->capture_default_str();
  view->add_option("--splat-scale", view_options.splat_scale, "factor on every splat's radius")
      ->capture_default_str();

  auto* report = app.add_subcommand(
      "report", "Plots and report.md of a training run (loss, Gaussians, drops, IoU per class)");
  sadsplat::viz::ReportOptions report_options;
  report->add_option("RUN", report_options.run, "run directory")->required();
  report->add_option("--baseline", report_options.baseline, "a run to compare with");
  report->add_option("--out", report_options.out, "output directory (default RUN/report)");
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help / --version print and succeed; every usage error is one line and exit status 2
    // (CLI11's own codes vary by error kind, and it prints two lines).
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "sadsplat: usage error: " << e.what() << " (see sadsplat --help)\n";
    return 2;
  }
  sadsplat::gaussians::setCpuThreads();
  try {
    if (*info) {
      std::cout << sadsplat::io::describeFile(info_path);
    } else if (*import) {
      const auto start = Clock::now();
      const auto scene = sadsplat::io::importScene(import_dir, import_options);
      sadsplat::io::writeSceneCache(import_out, scene);
      std::cout << "imported " << scene.views.size() << " views, " << scene.points.size()
                << " points into " << import_out << " in " << secondsSince(start) << " s\n";
    } else if (*convert) {
      sadsplat::io::ConvertOptions options;
      options.spz_version = convert_spz_version;
      const std::string note = sadsplat::io::convertCloudFile(convert_in, convert_out, options);
      if (!note.empty()) std::cerr << "sadsplat: note: " << note << "\n";
    } else if (*extract) {
      if (sadsplat::io::isDirectory(extract_in)) {
        // A run directory: its model and its class list.
        if (extract_classes.empty()) extract_classes = extract_in + "/classes.json";
        extract_in += "/model.ply";
      }
      std::uint32_t class_id = 0;
      if (extract_classes.empty()) {
        std::size_t used = 0;
        unsigned long id = 0;
        try {
          id = std::stoul(extract_class, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != extract_class.size() || id >= sadsplat::kUnlabelled) {
          throw sadsplat::Error(extract_class, "--class",
                                "a class id, or --classes FILE to use names");
        }
        class_id = static_cast<std::uint32_t>(id);
      } else {
        const auto classes = sadsplat::io::isSceneCache(extract_classes)
                                 ? sadsplat::io::readSceneCache(extract_classes).classes
                                 : sadsplat::io::readClassesJson(extract_classes);
        sadsplat::semantic_drop::ClassExtraction<sadsplat::GaussianPoint> by_name;
        by_name.setClassName(extract_class, classes);
        class_id = by_name.getClassId();
      }
      if (sadsplat::io::cloudKind(extract_in) == sadsplat::io::CloudKind::kSemantic) {
        extractClass<pcl::PointXYZRGBL>(extract_in, extract_out, class_id, extract_negative,
                                        sadsplat::io::readSemanticCloud,
                                        sadsplat::io::writeSemanticCloud);
      } else {
        extractClass<sadsplat::GaussianPoint>(extract_in, extract_out, class_id, extract_negative,
                                              [](const std::string& path) {
                                                return sadsplat::io::readGaussians(path);
                                              },
                                              sadsplat::io::writeGaussians);
      }
    } else if (*synth_cmd) {
      if (synth_args.out.empty() && synth_args.cache.empty()) {
        throw sadsplat::Error("<command line>", "synth", "--out DIR and/or --cache FILE");
      }
      return runSynth(synth_args);
    } else if (*train) {
      sadsplat::gaussians::TrainConfig config;
      if (!train_config_file.empty()) {
        config = sadsplat::gaussians::TrainConfig::fromJson(
            sadsplat::io::readWholeFile(train_config_file), train_config_file);
      }
      if (train_iterations > 0) config.iterations = train_iterations;
      if (!train_device.empty()) config.device = train_device;
      if (train_seed >= 0) config.seed = static_cast<std::uint64_t>(train_seed);
      if (!train_drop.empty()) config.drop = train_drop;
      if (train_p_base >= 0) config.p_base = train_p_base;
      if (train_lambda_l0 >= 0) config.lambda_l0 = train_lambda_l0;
      if (train_l0_from >= 0) config.lambda_l0_from = train_l0_from;
      if (train_l0_ramp >= 0) config.lambda_l0_ramp = train_l0_ramp;
      if (train_l0_importance >= 0) config.l0_importance = train_l0_importance;
      if (train_recovery >= 0) config.recovery_iterations = train_recovery;
      if (train_recovery_prune >= 0) config.recovery_prune = train_recovery_prune;
      if (train_views_per_step > 0) config.views_per_step = train_views_per_step;
      if (train_prune_floaters) config.prune_floaters = true;
      // --nproc N starts ranks 1..N-1 as copies of this command (they see RANK and start none).
      std::optional<sadsplat::distributed::LocalRanks> local_ranks;
      if (train_nproc > 0 && std::getenv("RANK") == nullptr) {
        local_ranks.emplace(train_nproc, std::vector<std::string>(argv + 1, argv + argc));
        sadsplat::gaussians::setCpuThreads();
      }
      const auto rank_env = sadsplat::distributed::RankEnvironment::fromProcessEnvironment();
      const bool quiet_rank = rank_env && rank_env->rank != 0;
      sadsplat::pipeline::TrainRunOptions options;
      if (train_batch_schedule) {
        config =
            config.forGlobalBatch(config.views_per_step * (rank_env ? rank_env->world_size : 1));
      }
      if (rank_env) {
        // Every rank of a group, also a group of one (its all-reduce then costs what it costs).
        if (config.device.rfind("cuda", 0) == 0) sadsplat::distributed::bindLocalGpu(*rank_env);
        options.collective = sadsplat::distributed::joinGroup(*rank_env, config.device);
      }
      options.scene = train_scene;
      options.out = train_out;
      options.scale = train_scale;
      options.resume = train_resume;
      options.profile = train_profile;
      options.progress = quiet_rank ? nullptr : &std::cout;
      options.stop = &g_stop;
      std::signal(SIGINT, requestStop);
      std::signal(SIGTERM, requestStop);
      const double seconds = sadsplat::pipeline::trainRun(options, config);
      if (local_ranks) local_ranks->waitAll();
      if (!quiet_rank) {
        std::cout << "trained in " << seconds << " s; model in " << train_out << "/model.ply\n";
      }
    } else if (*pseudo) {
      pseudo_options.builtin.geometry = !pseudo_no_geometry;
      pseudo_options.builtin.scale_region_size = !pseudo_fixed_region_size;
      using sadsplat::pseudo_labels::MaskGenerator;
      pseudo_options.builtin.targets = pseudo_targets == "graph" ? MaskGenerator::kGraph
                                       : pseudo_targets == "multiscale"
                                           ? MaskGenerator::kSlicMultiscale
                                           : MaskGenerator::kSlic;
      pseudo_options.filter.per_class = pseudo_filter == "per-class";
      pseudo_options.filter.scale = pseudo_scale == "log-odds"
                                        ? sadsplat::pseudo_labels::ScoreScale::kLogOdds
                                        : sadsplat::pseudo_labels::ScoreScale::kScore;
      pseudo_options.progress = &std::cout;
      std::cout << sadsplat::pipeline::pseudoLabelRun(pseudo_options);
    } else if (*table) {
#if SADSPLAT_HAVE_VIZ
      if (!table_plots.empty()) rerunUnderXvfbIfHeadless(argc, argv);  // before any output
#endif
      const auto runs = sadsplat::eval::readExperimentRuns(table_results);
      const std::string text = sadsplat::eval::experimentTables(runs, table_baseline);
      if (!table_out.empty()) {
        sadsplat::io::writeFileAtomically(table_out, [&](std::ostream& o) { o << text; });
      }
      std::cout << text;
      if (!table_plots.empty()) {
#if SADSPLAT_HAVE_VIZ
        for (const std::string& path : sadsplat::viz::writeFrontierCharts(
                 table_plots, sadsplat::eval::frontierPoints(runs, table_baseline), table_baseline,
                 {table_goal_fewer, table_goal_psnr})) {
          std::cout << "wrote " << path << "\n";
        }
#else
        throw sadsplat::Error(table_plots, "--plots", "a build with VTK (charts)",
                              "this sadsplat was built without it");
#endif
      }
    } else if (*evaluate) {
      std::cout << sadsplat::pipeline::evalRun(eval_run, eval_scene);
#if SADSPLAT_HAVE_VIZ
    } else if (*view) {
      if (!view_options.screenshot.empty()) rerunUnderXvfbIfHeadless(argc, argv);
      view_options.color = sadsplat::viz::parseColorMode(view_color);
      parseSize(view_size, &view_options.width, &view_options.height);
      std::stringstream names(view_classes);
      for (std::string name; std::getline(names, name, ',');) {
        if (!name.empty()) view_options.classes.push_back(name);
      }
      std::vector<sadsplat::viz::ViewModel> models = {sadsplat::viz::loadViewModel(view_model)};
      if (!view_compare.empty()) models.push_back(sadsplat::viz::loadViewModel(view_compare));
      sadsplat::viz::showModels(models, view_options, &std::cout);
    } else if (*report) {
      rerunUnderXvfbIfHeadless(argc, argv);
      std::cout << "wrote " << sadsplat::viz::writeTrainingReport(report_options) << "\n";
#endif
    } else if (*demo) {
      return sadsplat::pipeline::runDemo(demo_out, demo_iterations, std::cout, demo_baseline);
    }
  } catch (const sadsplat::pipeline::TrainingInterrupted& e) {
    std::cerr << "\nsadsplat: interrupted: " << e.what() << "\n";
    return 130;
  } catch (const sadsplat::Error& e) {
    std::cerr << "sadsplat: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "sadsplat: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
