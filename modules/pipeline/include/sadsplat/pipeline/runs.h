#pragma once
/// \file runs.h
/// \brief The jobs behind `sadsplat train`, `sadsplat eval` and `sadsplat demo`.
///
/// A run directory holds: config.json (the exact configuration), run.json (scene path, device,
/// iterations done, training seconds), checkpoint.bin (latest training state, written every
/// checkpoint_interval iterations and at the end), model.ply (3DGS PLY with semantic
/// properties), model.pcd (the same Gaussians as PCD), model_semantic.pcd and model_semantic.ply
/// (the plain semantic cloud: centre, class colour, class id), classes.json, and after evaluation
/// metrics.json and panels/*.png.

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/schedule.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pipeline {

/// \brief Loads a scene directory (imported at `scale`, needs OpenCV; said on `progress` when
/// not null) or a scene cache file.
io::Scene loadScene(const std::string& path, double scale = 0.5, std::ostream* progress = nullptr);

/// \brief Options of a training run.
struct TrainRunOptions {
  std::string scene;    ///< scene directory or cache
  std::string out;      ///< run directory (created)
  double scale = 0.5;   ///< import scale for scene directories (paper: half resolution)
  bool resume = false;  ///< continue from out/checkpoint.bin
  /// The schedule's rules (gaussians::resolveSchedule), applied once to the configuration given
  /// to trainRun; a resumed run keeps its config.json and takes only the resolved iterations.
  gaussians::ScheduleRequest schedule;
  std::ostream* progress = nullptr;  ///< live progress line (carriage returns), or none
  /// Set (e.g. by a SIGINT / SIGTERM handler) to stop after the current iteration: the run
  /// writes its checkpoint and run.json, then throws TrainingInterrupted.
  const std::atomic<bool>* stop = nullptr;
  /// Time every phase of every iteration on this clock (gaussians::StepProfile::Clock: waiting
  /// for the device at each boundary, or the host's clock) and write the table to out/profile.md
  /// and to `progress`; none: no profile.
  std::optional<gaussians::StepProfile::Clock> profile;
  /// Train as one rank of a data-parallel group (distributed::joinGroup); only rank 0 writes the
  /// run directory, every rank resumes from its checkpoint.
  gaussians::Collective::Ptr collective;
};

/// \brief Thrown by trainRun when `stop` was set: the checkpoint of `iteration` is written and
/// `sadsplat train --resume` continues exactly.
class TrainingInterrupted : public Error {
 public:
  TrainingInterrupted(const std::string& run, int iteration);
  int iteration() const { return iteration_; }

 private:
  int iteration_;
};

/// \brief Resolves the schedule of `config` (options.schedule, said on `progress`), trains and
/// writes the run directory. Returns the training time in seconds.
///
/// Faults lose nothing: the checkpoint, model and logs are written atomically; a non-finite loss
/// stops the run with an error naming the iteration, before the next checkpoint, so the last
/// checkpoint holds the last good state; running out of CUDA memory is an error naming the
/// Gaussian count and what to change.
/// \throws sadsplat::Error on bad input, a diverged training or no GPU memory;
/// TrainingInterrupted when `stop` was set
double trainRun(const TrainRunOptions& options, const gaussians::TrainConfig& config);

/// \brief A trained run opened for rendering: its scene, configuration and model (the trainer
/// restored from checkpoint.bin).
struct OpenedRun {
  std::string dir;
  std::string scene_path;  ///< the scene the run trained on (or the override)
  double scale = 0.5;      ///< the import scale of a scene directory
  double train_seconds = 0;
  io::Scene scene;
  gaussians::TrainConfig config;
  std::unique_ptr<gaussians::Trainer> trainer;
};

/// \brief Opens a run directory (run.json, config.json, checkpoint.bin) on its scene or on
/// `scene_override`.
/// \throws sadsplat::Error naming the run's file and field
OpenedRun openRun(const std::string& run_dir, const std::string& scene_override = "",
                  double scale = 0.5);

/// \brief The scene directory a run's scene was imported from (its images/ hold the photos at
/// their imported-from size), or "" when there is none: the run's scene itself, or a cache's
/// recorded source (a relative source is looked for from the folders above the cache).
std::string sceneDirectoryOf(const OpenedRun& run);

/// \brief Evaluates a run directory on its scene (or `scene_override`): writes metrics.json and
/// panels/, returns the metrics.json text.
std::string evalRun(const std::string& run_dir, const std::string& scene_override = "",
                    double scale = 0.5);

/// \brief `sadsplat demo`: generates the small city scene, writes its pseudo-labels (built-in
/// backend, report in OUT/pseudo_labels), trains on CPU with the full semantic-aware drop,
/// evaluates, prints a table to `out`. `baseline` skips pseudo-labels and drop (the paper's
/// Net-1). Returns 0 on success.
int runDemo(const std::string& out_dir, int iterations, std::ostream& out, bool baseline = false);

}  // namespace pipeline
}  // namespace sadsplat
