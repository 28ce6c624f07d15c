#include "sadsplat/pipeline/runs.h"

#include <nlohmann/json.hpp>

#include <c10/util/Exception.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <sstream>

#include "background_task.h"
#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/eval/evaluation.h"
#include "sadsplat/gaussians/densification.h"
#include "sadsplat/gaussians/initialization.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/io/semantic_ply.h"
#include "sadsplat/io/train_log.h"
#include "sadsplat/pipeline/pseudo_label_run.h"
#include "sadsplat/semantic_drop/drop_strategy.h"

#if SADSPLAT_HAVE_OPENCV
#include "sadsplat/synth/aerial_benchmark.h"
#include "sadsplat/synth/scene_writer.h"
#endif

namespace sadsplat {
namespace pipeline {
namespace {

// Iterations between two reads of the loss values (train log records, progress line, the
// divergence check); the steps in between run without waiting for the device.
constexpr int kLossInterval = 10;

using Clock = std::chrono::steady_clock;
using io::isDirectory;
using io::makeDirectory;
using io::pathExists;

void writeText(const std::string& path, const std::string& text) {
  io::writeFileAtomically(path, [&](std::ostream& out) { out << text; });
}

std::string formatSeconds(double s) {
  std::ostringstream out;
  const int total = static_cast<int>(std::round(s));
  out << total / 60 << "m" << std::setw(2) << std::setfill('0') << total % 60 << "s";
  return out.str();
}

void writeRunJson(const std::string& dir, const std::string& scene, double scale,
                  const std::string& device, int iterations, double seconds) {
  // Absolute, so that `eval` finds the scene from any working directory.
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(scene, error);
  const nlohmann::json j = {{"scene", error ? scene : absolute.lexically_normal().string()},
                            {"scale", scale},
                            {"device", device},
                            {"iterations", iterations},
                            {"train_seconds", seconds}};
  writeText(dir + "/run.json", j.dump(2) + "\n");
}

void writeModel(const std::string& dir, const gaussians::Trainer& trainer,
                const std::vector<ClassInfo>& classes) {
  const auto cloud = trainer.toCloud();
  io::PlyWriteOptions ply;
  // A scene without classes trains plain 3DGS: a standard PLY without semantic properties.
  ply.semantic = !classes.empty();
  ply.feature_dim = trainer.config().feature_dim;
  io::writeGaussianPly(dir + "/model.ply", cloud, ply);
  io::savePcd(dir + "/model.pcd", cloud);
  if (classes.empty()) return;
  const auto semantic = toSemanticCloud(cloud, classes);
  io::savePcd(dir + "/model_semantic.pcd", semantic);
  io::writeSemanticPly(dir + "/model_semantic.ply", semantic);
}

// RUN/run.json as a JSON object, or a sadsplat::Error naming it.
nlohmann::json readRunJson(const std::string& run_dir) {
  const std::string path = run_dir + "/run.json";
  try {
    nlohmann::json j = nlohmann::json::parse(io::readWholeFile(path));
    if (!j.is_object()) throw Error(path, "top level", "a JSON object", j.type_name());
    return j;
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "JSON", "the run.json that `sadsplat train` writes", e.what());
  }
}

// The train log's records of one step: a drop and a closed-gate removal when they happened, and
// the losses every 10 iterations (as the progress line) and at the last one.
void logStep(io::TrainLogWriter& log, const gaussians::StepStats& s, double seconds, bool last) {
  if (s.dropped > 0) {
    io::TrainLogRecord r;
    r.type = "drop";
    r.iteration = s.iteration;
    r.removed = s.dropped;
    r.gaussians = s.num_gaussians;
    r.low_confidence = s.drop.removed_low_confidence;
    r.unseen = s.drop.removed_unseen;
    r.closed_gate = s.drop.removed_closed_gate;
    log.append(r);
  }
  if (s.removed_closed_gates > 0) {
    io::TrainLogRecord r;
    r.type = "closed_gates";
    r.iteration = s.iteration;
    r.removed = s.removed_closed_gates;
    r.gaussians = s.num_gaussians;
    log.append(r);
  }
  if (s.recovery_started) {
    io::TrainLogRecord r;
    r.type = "recovery";
    r.iteration = s.iteration;
    r.removed = s.recovery_closed_gates + s.recovery_pruned;
    r.closed_gate = s.recovery_closed_gates;
    r.gaussians = s.num_gaussians;
    log.append(r);
  }
  if (s.losses_read && (s.iteration % kLossInterval == 0 || last)) {
    io::TrainLogRecord r;
    r.iteration = s.iteration;
    r.loss = s.loss;
    r.rgb_loss = s.rgb_loss;
    r.semantic_loss = s.semantic_loss;
    r.gaussians = s.num_gaussians;
    r.seconds = seconds;
    log.append(r);
  }
}

}  // namespace

TrainingInterrupted::TrainingInterrupted(const std::string& run, int iteration)
    : Error(run, "training", "to run to the end",
            "an interrupt at iteration " + std::to_string(iteration) +
                "; checkpoint written, continue with `sadsplat train ... --resume`"),
      iteration_(iteration) {}

io::Scene loadScene(const std::string& path, double scale, std::ostream* progress) {
  if (isDirectory(path)) {
    io::ImportOptions options;
    options.scale = scale;
    if (progress != nullptr) {
      *progress << "importing " << path << " at image scale " << scale
                << " (--scale; `sadsplat import` writes a scene cache to skip this step)\n";
    }
    return io::importScene(path, options);
  }
  return io::readSceneCache(path);
}

double trainRun(const TrainRunOptions& o, const gaussians::TrainConfig& config_in) {
  // Rank 0 of a data-parallel group (or a single process) writes the run; the ranks hold the
  // same Gaussians at every step.
  const bool writer = !o.collective || o.collective->rank() == 0;
  if (writer) makeDirectory(o.out);
  const std::string checkpoint = o.out + "/checkpoint.bin";
  const gaussians::ResolvedSchedule schedule = gaussians::resolveSchedule(config_in, o.schedule);
  gaussians::TrainConfig config = schedule.config;
  double previous_seconds = 0;
  if (o.resume) {
    if (!pathExists(checkpoint))
      throw Error(checkpoint, "file", "a checkpoint to resume from", "missing");
    // The run's own configuration wins: resuming continues the same run (to the iterations asked).
    config = gaussians::TrainConfig::fromJson(io::readWholeFile(o.out + "/config.json"),
                                              o.out + "/config.json");
    config.iterations = schedule.config.iterations;
    const auto run = readRunJson(o.out);
    previous_seconds = run.contains("train_seconds") && run["train_seconds"].is_number()
                           ? run["train_seconds"].get<double>()
                           : 0.0;
  } else if (o.progress) {
    for (const std::string& note : schedule.notes) *o.progress << note << "\n";
  }
  const io::Scene scene = loadScene(o.scene, o.scale, o.progress);
  if (o.progress && scene.classes.empty()) {
    *o.progress << "RGB only: the scene has no classes.json, so no semantic head (plain 3DGS"
                << (config.drop == "none" ? ""
                                          : ", drop " + config.drop + " without confidence maps")
                << ")\n";
  } else if (o.progress) {
    int labelled = 0, pseudo = 0;
    for (const io::View& v : scene.views) {
      if (!v.train) continue;
      if (v.labelled && !v.labels.empty())
        ++labelled;
      else if (!v.pseudo.empty())
        ++pseudo;
    }
    *o.progress << "semantic supervision: " << labelled << " labelled views, "
                << (config.use_pseudo_labels ? pseudo : 0) << " pseudo-labelled views"
                << (pseudo == 0 ? " (run `sadsplat pseudo-labels` on the scene cache to add them)"
                                : "")
                << "; drop " << config.drop << " with confidence maps of "
                << (pseudo > 0 ? "the pseudo-label backend + ground truth"
                               : "the ground truth only")
                << "\n";
  }
  if (o.progress && !o.resume && gaussians::initialisesRandomly(config.init, scene.points.size())) {
    *o.progress << "initialisation: up to " << config.init_random_count
                << " random points in the training cameras' common view"
                << (config.init == "random" ? "" : " (the scene has no sparse points)") << "\n";
  }
  gaussians::Trainer trainer(scene, config);
  // What the trainer runs is what the loop counts, the log prints and config.json records.
  config = trainer.config();
  trainer.setDropStrategy(semantic_drop::makeDropStrategy(config));
  trainer.setCollective(o.collective);
  if (o.resume) trainer.loadCheckpoint(checkpoint);
  if (writer) writeText(o.out + "/config.json", trainer.config().toJson());
  if (o.progress && !o.resume) {
    *o.progress << "schedule: " << gaussians::describeDefaultDensification(trainer.config())
                << "\n";
  }
  gaussians::StepProfile::Ptr profile;
  if (o.profile) {
    profile = std::make_shared<gaussians::StepProfile>(
        config.device == "cuda" ? at::Device(at::kCUDA, 0) : at::Device(at::kCPU), *o.profile);
    trainer.setProfile(profile);
  }
  const auto start = Clock::now();
  auto seconds = [&] {
    return previous_seconds + std::chrono::duration<double>(Clock::now() - start).count();
  };
  const int first = trainer.iteration();
  std::optional<io::TrainLogWriter> log;
  if (writer) log.emplace(o.out + "/train_log.jsonl", o.resume ? first : -1);
  // Fault injection for the crash tests (tests/apps/test_faults.cpp): the process kills itself
  // with SIGKILL right after this iteration's step, before its checkpoint.
  const char* kill_at_text = std::getenv("SADSPLAT_FAULT_KILL_AT_ITERATION");
  // SADSPLAT_FAULT_KILL_RANK limits it to one rank of a data-parallel group.
  const char* kill_rank_text = std::getenv("SADSPLAT_FAULT_KILL_RANK");
  const bool kill_this_rank = kill_rank_text == nullptr ||
                              (o.collective && o.collective->rank() == std::atoi(kill_rank_text));
  const int kill_at = kill_at_text && kill_this_rank ? std::atoi(kill_at_text) : -1;
  int last_checkpoint = first;
  // The checkpoint and run.json go together: run.json says which iteration the checkpoint holds.
  // The training waits only for the copy of its state to host memory; the files are written on
  // another thread (a few hundred MB at 10^5-10^6 Gaussians: 0.3 s a checkpoint on a GPU
  // machine's disk, 6 % of a 7000-iteration training there).
  BackgroundTask checkpoint_writes;
  const auto checkpointInBackground = [&] {
    if (!writer) return;
    const int iteration = trainer.iteration();
    const double elapsed = seconds();
    // The archive holds tensor handles: copying the lambda shares the snapshot's storage.
    checkpoint_writes.start(
        [&o, &config, checkpoint, snapshot = trainer.checkpointSnapshot(), iteration, elapsed] {
          gaussians::writeTensorArchive(checkpoint, snapshot);
          writeRunJson(o.out, o.scene, o.scale, config.device, iteration, elapsed);
        });
    last_checkpoint = iteration;
  };
  const auto checkpointNow = [&] {
    checkpointInBackground();
    checkpoint_writes.wait();
  };
  // A stop request (SIGINT / SIGTERM) reaches data-parallel ranks at different moments: they
  // agree on it every few iterations (a one-number maximum over the group), so that all stop
  // after the same iteration, the one rank 0's checkpoint holds.
  const int stop_agreement_interval = 10;
  const auto stopRequested = [&] {
    const bool here = o.stop != nullptr && o.stop->load();
    if (!o.collective) return here;
    if (trainer.iteration() % stop_agreement_interval != 0) return false;
    at::Tensor flag =
        at::full({1}, here ? 1.f : 0.f,
                 at::TensorOptions().device(config.device == "cuda" ? at::Device(at::kCUDA, 0)
                                                                    : at::Device(at::kCPU)));
    o.collective->max(flag);
    return flag.item<float>() > 0;
  };
  int rendered_again = 0;  // CUDA steps whose tile lists, sized from earlier counts, were short
  // Said once: a model at the cap has stopped growing because of it, not because the densifier
  // converged (a real survey reached 3 M Gaussians by iteration 6000 of the long schedule).
  bool said_cap = o.resume && trainer.numGaussians() >= config.max_gaussians;
  while (trainer.iteration() < config.iterations) {
    if (stopRequested()) {
      checkpointNow();
      throw TrainingInterrupted(o.out, trainer.iteration());
    }
    gaussians::StepStats stats;
    // The losses are read where the log and the progress line show them (every 10th iteration
    // and the last): the steps in between do not wait for the GPU.
    const int next = trainer.iteration() + 1;
    const bool read_losses = next % kLossInterval == 0 || next == config.iterations;
    try {
      stats = trainer.step(read_losses);
    } catch (const c10::Error& e) {
      if (std::string(e.what()).find("out of memory") == std::string::npos) throw;
      throw Error(o.out, "training at iteration " + std::to_string(trainer.iteration() + 1),
                  "enough GPU memory for " + std::to_string(trainer.numGaussians()) +
                      " Gaussians (lower max_gaussians or raise densify_grad_threshold in "
                      "--config, train at a smaller --scale, or free the GPU)",
                  "CUDA out of memory");
    }
    const int it = stats.iteration;
    rendered_again += stats.rendered_again ? 1 : 0;
    if (stats.losses_read && !std::isfinite(stats.loss)) {
      const std::string kept = last_checkpoint > 0 ? "; checkpoint.bin keeps iteration " +
                                                         std::to_string(last_checkpoint)
                                                   : "; no checkpoint was written yet";
      throw Error(o.out, "training at iteration " + std::to_string(it), "a finite loss",
                  std::string(std::isnan(stats.loss) ? "NaN" : "infinity") + " (diverged" + kept +
                      "; lower the learning rates in the configuration)");
    }
    if (it == kill_at) {
      checkpoint_writes.wait();  // the fault tests kill after the last checkpoint is on disk
      std::raise(SIGKILL);
    }
    gaussians::enterPhase(profile.get(), "log and progress");
    if (log) logStep(*log, stats, seconds(), it == config.iterations);
    if (!said_cap && stats.num_gaussians >= config.max_gaussians) {
      said_cap = true;
      if (log) {
        io::TrainLogRecord r;
        r.type = "max_gaussians_reached";
        r.iteration = it;
        r.gaussians = stats.num_gaussians;
        log->append(r);
      }
      if (o.progress) {
        *o.progress << "\n[densify] iteration " << it << ": the model reached max_gaussians ("
                    << config.max_gaussians << "); densification adds no more. "
                    << io::kMaxGaussiansAdvice << "\n";
      }
    }
    if (stats.dropped > 0 && o.progress) {
      const gaussians::DropDecision& d = stats.drop;
      *o.progress << "\n[drop] iteration " << it << ": removed " << stats.dropped << " Gaussians ("
                  << config.drop << " " << config.drop_rule << ", P_base " << config.p_base
                  << (config.drop_rule == "balanced"
                          ? ", pressure " + std::to_string(stats.drop_pressure).substr(0, 6)
                          : std::string())
                  << "), " << stats.num_gaussians
                  << " left; of the removed: " << d.removed_low_confidence << " with P_conf < 0.5 ("
                  << d.removed_unseen << " seen by no confidence map), " << d.removed_closed_gate
                  << " with P_nonzero < 0.5\n";
    }
    if (stats.removed_closed_gates > 0 && o.progress) {
      *o.progress << "\n[drop] end of training: removed " << stats.removed_closed_gates
                  << " Gaussians with a closed gate (they render nothing), " << stats.num_gaussians
                  << " left\n";
    }
    if (stats.recovery_started && o.progress) {
      *o.progress << "\n[recovery] iteration " << it
                  << ": gates folded into the opacities; removed " << stats.recovery_closed_gates
                  << " Gaussians with a closed gate and " << stats.recovery_pruned
                  << " least contributing ones, " << stats.num_gaussians << " left; "
                  << config.recovery_iterations
                  << " iterations without gates, L0 and drops follow\n";
    }
    if (stats.removed_floaters > 0 && o.progress) {
      std::string rule;
      if (config.floater_min_views > 0) {
        rule = "seen by fewer than " + std::to_string(config.floater_min_views) + " training views";
      }
      if (config.floater_max_scale > 0) {
        std::ostringstream size;
        size << "larger than " << config.floater_max_scale << " x the scene extent";
        rule += (rule.empty() ? "" : " or ") + size.str();
      }
      *o.progress << "\n[floaters] end of training: removed " << stats.removed_floaters
                  << " Gaussians " << rule << ", " << stats.num_gaussians << " left\n";
    }
    if (o.progress && stats.losses_read) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      const double rate = (it - first) / std::max(1e-9, elapsed);
      // Formatted apart so that the fixed-point state does not leak into the caller's stream.
      std::ostringstream line;
      line << "\r[" << it << "/" << config.iterations << "] loss " << std::fixed
           << std::setprecision(4) << stats.loss << " (rgb " << stats.rgb_loss << ", sem "
           << stats.semantic_loss << ")  gaussians " << stats.num_gaussians << "  "
           << std::setprecision(1) << rate << " it/s  ETA "
           << formatSeconds((config.iterations - it) / std::max(rate, 1e-9)) << "   ";
      *o.progress << line.str() << std::flush;
    }
    if (config.checkpoint_interval > 0 && it % config.checkpoint_interval == 0 &&
        it < config.iterations) {
      gaussians::enterPhase(profile.get(), "checkpoints");
      checkpointInBackground();
    }
    if (profile) profile->leave();
  }
  checkpoint_writes.wait();
  if (o.progress) *o.progress << "\n";
  if (rendered_again > 0 && o.progress) {
    *o.progress << "[tile lists] " << rendered_again << (rendered_again == 1 ? " step" : " steps")
                << " rendered again: a tile list sized from earlier renders was short "
                   "(tile_list_margin "
                << config.tile_list_margin << ")\n";
  }
  if (profile) {
    const std::string table = "Training time per phase (" + config.device +
                              (*o.profile == gaussians::StepProfile::Clock::kHost
                                   ? ", the host's clock: no phase waits for the device"
                                   : ", each phase boundary waits for the device") +
                              "):\n\n" + profile->table();
    if (writer) {
      writeText(o.out + "/profile.md", table);
      writeText(o.out + "/profile_operators.md",
                "ATen operator calls per iteration by phase of the training step (nested calls "
                "included; at least 0.05 per iteration):\n" +
                    profile->operatorTable());
    }
    if (o.progress) *o.progress << table;
  }
  const double total = seconds();
  if (!writer) return total;
  trainer.saveCheckpoint(checkpoint);
  writeRunJson(o.out, o.scene, o.scale, config.device, trainer.iteration(), total);
  writeModel(o.out, trainer, scene.classes);
  if (!scene.classes.empty()) io::writeClassesJson(o.out + "/classes.json", scene.classes);
  if (scene.georeference) {
    // The model's frame: east-north-up metres around the origin (for GIS outputs and viewers).
    writeText(o.out + "/georeference.json", io::georeferenceToJson(*scene.georeference));
  }
  return total;
}

OpenedRun openRun(const std::string& run_dir, const std::string& scene_override, double scale) {
  const auto run = readRunJson(run_dir);
  if (scene_override.empty() && !(run.contains("scene") && run["scene"].is_string())) {
    throw Error(run_dir + "/run.json", "scene", "the path of the run's scene (a string)",
                run.contains("scene") ? run["scene"].dump().substr(0, 40) : std::string("missing"));
  }
  OpenedRun o;
  o.dir = run_dir;
  o.scene_path = scene_override.empty() ? run["scene"].get<std::string>() : scene_override;
  o.scale = scene_override.empty() && run.contains("scale") && run["scale"].is_number()
                ? run["scale"].get<double>()
                : scale;
  o.train_seconds = run.value("train_seconds", 0.0);
  o.config = gaussians::TrainConfig::fromJson(io::readWholeFile(run_dir + "/config.json"),
                                              run_dir + "/config.json");
  o.scene = loadScene(o.scene_path, o.scale);
  o.trainer = std::make_unique<gaussians::Trainer>(o.scene, o.config);
  o.trainer->setDropStrategy(semantic_drop::makeDropStrategy(o.config));
  o.trainer->loadCheckpoint(run_dir + "/checkpoint.bin");
  return o;
}

std::string sceneDirectoryOf(const OpenedRun& run) {
  if (io::isDirectory(run.scene_path)) return run.scene_path;
  const std::string& source = run.scene.source;
  if (source.empty()) return "";
  if (io::isDirectory(source)) return source;
  // A relative path is the one `import` was given, from the directory it ran in: usually an
  // ancestor of the cache's folder.
  if (source[0] != '/') {
    std::filesystem::path dir = std::filesystem::absolute(run.scene_path).parent_path();
    for (; !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      if (io::isDirectory((dir / source).string())) return (dir / source).string();
    }
  }
  return "";
}

std::string evalRun(const std::string& run_dir, const std::string& scene_override, double scale) {
  const OpenedRun run = openRun(run_dir, scene_override, scale);
  makeDirectory(run_dir + "/panels");
  const eval::EvalResult result = eval::evaluate(*run.trainer, run.scene, run_dir + "/panels");
  eval::RunFacts facts;
  facts.num_gaussians = run.trainer->numGaussians();
  facts.iterations = run.trainer->iteration();
  facts.train_seconds = run.train_seconds;
  facts.device = run.config.device;
  const std::string text = eval::metricsJson(result, run.scene.classes, facts);
  writeText(run_dir + "/metrics.json", text);
  return text;
}

int runDemo(const std::string& out_dir, int iterations, std::ostream& out, bool baseline) {
#if SADSPLAT_HAVE_OPENCV
  makeDirectory(out_dir);
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
  if (!baseline) config.drop = "full";
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
