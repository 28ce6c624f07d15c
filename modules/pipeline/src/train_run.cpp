#include "sadsplat/pipeline/train_run.h"

#include <c10/util/Exception.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>

#include "background_task.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/gaussians/device.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/georeference.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/semantic_ply.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/semantic_drop/drop_strategy.h"
#include "training_report.h"

namespace sadsplat {
namespace pipeline {
namespace {

at::Device deviceOf(const gaussians::TrainConfig& config) {
  return gaussians::deviceNamed(gaussians::choiceName(config.device), "<config>");
}

// The configuration a run trains with: the schedule resolved, or for a resumed run its own
// config.json (resuming continues the same run) to the iterations asked. Sets the seconds the
// run had trained before.
gaussians::TrainConfig runConfiguration(const TrainRunOptions& o,
                                        const gaussians::ResolvedSchedule& schedule,
                                        const io::RunDirectory& dir, double* previous_seconds) {
  *previous_seconds = 0;
  if (!o.resume) {
    if (o.progress) {
      for (const std::string& note : schedule.notes) *o.progress << note << "\n";
    }
    return schedule.config;
  }
  if (!io::pathExists(dir.checkpoint()))
    throw Error(dir.checkpoint(), "file", "a checkpoint to resume from", "missing");
  gaussians::TrainConfig config =
      gaussians::TrainConfig::fromJson(io::readWholeFile(dir.config()), dir.config());
  config.iterations = schedule.config.iterations;
  *previous_seconds = dir.readRecord().train_seconds;
  return config;
}

void writeModel(const io::RunDirectory& dir, const gaussians::Trainer& trainer,
                const io::Scene& scene, std::ostream* progress) {
  const std::vector<ClassInfo>& classes = scene.classes;
  const auto cloud = labelledCloud(trainer, scene, progress);
  io::PlyWriteOptions ply;
  // A scene without classes trains plain 3DGS: a standard PLY without semantic properties.
  ply.semantic = !classes.empty();
  ply.feature_dim = trainer.config().feature_dim;
  io::writeGaussianPly(dir.model(), cloud, ply);
  io::savePcd(dir.modelPcd(), cloud);
  if (classes.empty()) return;
  const auto semantic = toSemanticCloud(cloud, classes);
  io::savePcd(dir.semanticPcd(), semantic);
  io::writeSemanticPly(dir.semanticPly(), semantic);
}

// Checkpoints and run.json, which go together (run.json says which iteration the checkpoint
// holds). The training waits only for the copy of its state to host memory; the files are
// written on another thread (a few hundred MB at 10^5-10^6 Gaussians: 0.3 s a checkpoint on a GPU
// machine's disk, 6 % of a 7000-iteration training there). Only the writer rank writes.
class Checkpoints {
 public:
  Checkpoints(const io::RunDirectory& dir, io::RunRecord record, bool writer, int first)
      : dir_(dir), record_(std::move(record)), writer_(writer), last_(first) {}
  void inBackground(const gaussians::Trainer& trainer, double seconds) {
    if (!writer_) return;
    io::RunRecord record = record_;
    record.iterations = trainer.iteration();
    record.train_seconds = seconds;
    // The archive holds tensor handles: copying the lambda shares the snapshot's storage.
    writes_.start([dir = dir_, record, snapshot = trainer.checkpointSnapshot()] {
      gaussians::writeTensorArchive(dir.checkpoint(), snapshot);
      dir.writeRecord(record);
    });
    last_ = trainer.iteration();
  }
  void now(const gaussians::Trainer& trainer, double seconds) {
    inBackground(trainer, seconds);
    writes_.wait();
  }
  void wait() { writes_.wait(); }
  int last() const { return last_; }

 private:
  io::RunDirectory dir_;
  io::RunRecord record_;
  bool writer_;
  int last_;
  BackgroundTask writes_;
};

// A stop request (SIGINT / SIGTERM) reaches data-parallel ranks at different moments: they agree
// on it every few iterations (a one-number maximum over the group), so that all stop after the
// same iteration, the one rank 0's checkpoint holds.
bool stopAgreed(const TrainRunOptions& o, const gaussians::Trainer& trainer) {
  const bool here = o.stop != nullptr && o.stop->load();
  if (!o.collective) return here;
  constexpr int kAgreementInterval = 10;
  if (trainer.iteration() % kAgreementInterval != 0) return false;
  at::Tensor flag =
      at::full({1}, here ? 1.f : 0.f, at::TensorOptions().device(deviceOf(trainer.config())));
  o.collective->max(flag);
  return flag.item<float>() > 0;
}

// Fault injection for the crash tests (tests/apps/test_faults.cpp): the iteration after whose step
// the process kills itself with SIGKILL (SADSPLAT_FAULT_KILL_AT_ITERATION; limited to one rank
// of a group by SADSPLAT_FAULT_KILL_RANK), or -1.
int faultKillIteration(const TrainRunOptions& o) {
  const char* at = std::getenv("SADSPLAT_FAULT_KILL_AT_ITERATION");
  const char* rank = std::getenv("SADSPLAT_FAULT_KILL_RANK");
  const bool this_rank =
      rank == nullptr || (o.collective && o.collective->rank() == std::atoi(rank));
  return at && this_rank ? std::atoi(at) : -1;
}

// One step; running out of CUDA memory becomes an error naming the Gaussian count and what to do.
gaussians::StepStats stepExplained(gaussians::Trainer& trainer, bool read_losses,
                                   const std::string& run) {
  try {
    return trainer.step(read_losses);
  } catch (const c10::Error& e) {
    if (std::string(e.what()).find("out of memory") == std::string::npos) throw;
    throw Error(run, "training at iteration " + std::to_string(trainer.iteration() + 1),
                "enough GPU memory for " + std::to_string(trainer.numGaussians()) +
                    " Gaussians (lower max_gaussians or raise densify_grad_threshold in "
                    "--config, train at a smaller --scale, or free the GPU)",
                "CUDA out of memory");
  }
}

void checkFinite(const gaussians::StepStats& stats, const std::string& run, int last_checkpoint) {
  if (!stats.losses_read || std::isfinite(stats.loss)) return;
  const std::string kept =
      last_checkpoint > 0 ? "; checkpoint.bin keeps iteration " + std::to_string(last_checkpoint)
                          : "; no checkpoint was written yet";
  throw Error(run, "training at iteration " + std::to_string(stats.iteration), "a finite loss",
              std::string(std::isnan(stats.loss) ? "NaN" : "infinity") + " (diverged" + kept +
                  "; lower the learning rates in the configuration)");
}

// The profile's tables, written to the run (by the writer) and returned for the terminal.
std::string profileTables(const gaussians::StepProfile& profile,
                          gaussians::StepProfile::Clock clock, const gaussians::TrainConfig& config,
                          const io::RunDirectory& dir, bool writer) {
  const std::string table = "Training time per phase (" + gaussians::choiceName(config.device) +
                            (clock == gaussians::StepProfile::Clock::kHost
                                 ? ", the host's clock: no phase waits for the device"
                                 : ", each phase boundary waits for the device") +
                            "):\n\n" + profile.table();
  if (writer) {
    io::writeTextFileAtomically(dir.profile(), table);
    io::writeTextFileAtomically(
        dir.profileOperators(),
        "ATen operator calls per iteration by phase of the training step (nested calls "
        "included; at least 0.05 per iteration):\n" +
            profile.operatorTable());
  }
  return table;
}

}  // namespace

TrainingInterrupted::TrainingInterrupted(const std::string& run, int iteration)
    : Error(run, "training", "to run to the end",
            "an interrupt at iteration " + std::to_string(iteration) +
                "; checkpoint written, continue with `sadsplat train ... --resume`"),
      iteration_(iteration) {}

double trainRun(const TrainRunOptions& o, const gaussians::TrainConfig& config) {
  // The views' pixels stay in a scene cache: the trainer reads each view from the file, holds
  // it on the device or (stream_views) reads it again for each step that uses it.
  return trainRun(o, config, loadScene(o.scene, o.scale, o.progress, ScenePixels::kLeftOnDisk));
}

void writeTrainedRun(const io::RunDirectory& dir, const gaussians::Trainer& trainer,
                     const io::Scene& scene, const io::RunRecord& record, std::ostream* progress) {
  trainer.saveCheckpoint(dir.checkpoint());
  dir.writeRecord(record);
  writeModel(dir, trainer, scene, progress);
  if (!scene.classes.empty()) io::writeClassesJson(dir.classes(), scene.classes);
  if (scene.georeference) {
    // The model's frame: east-north-up metres around the origin (for GIS outputs and viewers).
    io::writeTextFileAtomically(dir.georeference(), io::georeferenceToJson(*scene.georeference));
  }
}

double trainRun(const TrainRunOptions& o, const gaussians::TrainConfig& config_in,
                const io::Scene& scene) {
  // Rank 0 of a data-parallel group (or a single process) writes the run; the ranks hold the
  // same Gaussians at every step.
  const bool writer = !o.collective || o.collective->rank() == 0;
  if (writer) io::makeDirectory(o.out);
  const io::RunDirectory dir(o.out);
  double previous_seconds = 0;
  gaussians::TrainConfig config = runConfiguration(
      o, gaussians::resolveSchedule(config_in, o.schedule), dir, &previous_seconds);
  gaussians::Trainer trainer(scene, config);
  config = trainer.config();  // what the loop counts, the log prints and config.json records
  trainer.setDropStrategy(semantic_drop::makeDropStrategy(config));
  trainer.setCollective(o.collective);
  if (o.resume) trainer.loadCheckpoint(dir.checkpoint());
  const int first = trainer.iteration();
  TrainingReport report(o.progress, writer ? dir.trainLog() : "", o.resume ? first : -1);
  report.started(scene, config, o.resume);
  if (writer) io::writeTextFileAtomically(dir.config(), config.toJson());
  if (!o.resume) report.schedule(config);
  gaussians::StepProfile::Ptr profile;
  if (o.profile) {
    profile = std::make_shared<gaussians::StepProfile>(deviceOf(config), *o.profile);
    trainer.setProfile(profile);
  }
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return previous_seconds +
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  Checkpoints checkpoints(
      dir, io::RunRecord{o.scene, o.scale, gaussians::choiceName(config.device), first, 0}, writer,
      first);
  const int kill_at = faultKillIteration(o);
  report.atCap(o.resume && trainer.numGaussians() >= config.max_gaussians);
  report.begin(first);
  while (trainer.iteration() < config.iterations) {
    if (stopAgreed(o, trainer)) {
      checkpoints.now(trainer, seconds());
      throw TrainingInterrupted(o.out, trainer.iteration());
    }
    // The losses are read where the log and the progress line show them (every 10th iteration
    // and the last): the steps in between do not wait for the GPU.
    const int next = trainer.iteration() + 1;
    const gaussians::StepStats stats =
        stepExplained(trainer, next % kLossInterval == 0 || next == config.iterations, o.out);
    checkFinite(stats, o.out, checkpoints.last());
    if (stats.iteration == kill_at) {
      checkpoints.wait();  // the fault tests kill after the last checkpoint is on disk
      std::raise(SIGKILL);
    }
    gaussians::enterPhase(profile.get(), "log and progress");
    report.stepped(stats, config, seconds());
    if (config.checkpoint_interval > 0 && stats.iteration % config.checkpoint_interval == 0 &&
        stats.iteration < config.iterations) {
      gaussians::enterPhase(profile.get(), "checkpoints");
      checkpoints.inBackground(trainer, seconds());
    }
    if (profile) profile->leave();
  }
  checkpoints.wait();
  report.finished(config, profile ? profileTables(*profile, *o.profile, config, dir, writer) : "");
  const double total = seconds();
  if (!writer) return total;
  writeTrainedRun(dir, trainer, scene,
                  io::RunRecord{o.scene, o.scale, gaussians::choiceName(config.device),
                                trainer.iteration(), total},
                  o.progress);
  return total;
}

}  // namespace pipeline
}  // namespace sadsplat
