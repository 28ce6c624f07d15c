#include "sadsplat/pipeline/demo.h"

#include <chrono>
#include <iomanip>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/pseudo_label_run.h"
#include "sadsplat/pipeline/train_run.h"
#include "training_report.h"
#if SADSPLAT_HAVE_OPENCV
#include "sadsplat/synth/aerial_benchmark.h"
#include "sadsplat/synth/scene_writer.h"
#endif

namespace sadsplat {
namespace pipeline {
using Clock = std::chrono::steady_clock;

int runDemo(const std::string& out_dir, int iterations, std::ostream& out, bool baseline) {
#if SADSPLAT_HAVE_OPENCV
  io::makeDirectory(out_dir);
  const auto start = Clock::now();
  const std::string scene_dir = out_dir + "/city_demo";
  out << "[1/4] generating the demo city scene (" << scene_dir << ")\n";
  const auto scene = synth::generate(synth::SynthOptions::demo(synth::SceneKind::kCity, 0));
  synth::writeScene(scene, scene_dir);
  out << "      " << scene.views.size() << " views 320x180, " << scene.points.size()
      << " sparse points, " << formatSeconds(scene.seconds) << "\n";
  std::string train_scene = scene_dir;
  if (baseline) {
    out << "[2/4] pseudo-labels: skipped (--baseline)\n";
  } else {
    out << "[2/4] pseudo-labels of the unlabelled training views (built-in backend)\n";
    PseudoLabelRunOptions p;
    p.scene = scene_dir;
    p.scale = 1.0;
    p.out = out_dir + "/city_demo.cache";
    p.report_dir = out_dir + "/pseudo_labels";
    p.progress = &out;
    pseudoLabelRun(p);
    train_scene = p.out;
  }
  out << "[3/4] training " << iterations << " iterations on the CPU ("
      << (baseline ? "baseline: no pseudo-labels, no drop"
                   : "pseudo-labels + full semantic-aware drop")
      << ")\n";
  gaussians::TrainConfig config;
  config.iterations = iterations;
  if (!baseline) config.drop = gaussians::DropMode::kFull;
  TrainRunOptions o;
  o.scene = train_scene;
  o.out = out_dir + "/run";
  o.scale = 1.0;
  o.progress = &out;
  const double seconds = trainRun(o, config);
  out << "[4/4] evaluating the test views\n";
  const auto metrics = nlohmann::json::parse(evalRun(o.out));
  out << "\n| metric | value |\n|---|---|\n"
      << std::fixed << std::setprecision(2) << "| mIoU | " << 100 * metrics["miou"].get<double>()
      << " % |\n"
      << "| mAcc | " << 100 * metrics["macc"].get<double>() << " % |\n"
      << "| overall accuracy | " << 100 * metrics["oacc"].get<double>() << " % |\n"
      << "| PSNR | " << metrics["psnr"].get<double>() << " dB |\n"
      << "| SSIM | " << std::setprecision(3) << metrics["ssim"].get<double>() << " |\n"
      << "| Gaussians | " << metrics["num_gaussians"].get<std::int64_t>() << " |\n"
      << "| training time | " << std::setprecision(1) << seconds << " s |\n"
      << "| total time | " << std::chrono::duration<double>(Clock::now() - start).count()
      << " s |\n";
  out << "per-class IoU:";
  for (auto it = metrics["per_class_iou"].begin(); it != metrics["per_class_iou"].end(); ++it) {
    out << " " << it.key() << " "
        << (it.value().is_null() ? std::string("-")
                                 : std::to_string(it.value().get<double>()).substr(0, 5));
  }
  out << "\noutputs: " << o.out << " (model.ply, metrics.json, panels/)\n";
  return 0;
#else
  throw Error("<demo>", "build", "a sadsplat build with OpenCV (the demo generates its scene)",
              "a build without OpenCV");
#endif
}

}  // namespace pipeline
}  // namespace sadsplat
