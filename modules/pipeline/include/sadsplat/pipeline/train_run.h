#pragma once
/// \file train_run.h
/// \brief The job behind `sadsplat train`: the schedule resolved once, the training loop with
/// checkpoints, progress and the train log, and the run directory written (io::RunDirectory).

#include <atomic>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/schedule.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pipeline {

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

/// \brief As trainRun, on a scene already in memory (options.scene is what run.json records).
double trainRun(const TrainRunOptions& options, const gaussians::TrainConfig& config,
                const io::Scene& scene);

/// \brief Writes the files of a trained model into a run directory: checkpoint.bin, run.json
/// (`record`), model.ply / model.pcd, with classes the semantic clouds and classes.json, and a
/// georeferenced scene's georeference.json. `progress`: labelledCloud's line for the classes of
/// the Gaussians.
void writeTrainedRun(const io::RunDirectory& dir, const gaussians::Trainer& trainer,
                     const io::Scene& scene, const io::RunRecord& record,
                     std::ostream* progress = nullptr);

}  // namespace pipeline
}  // namespace sadsplat
