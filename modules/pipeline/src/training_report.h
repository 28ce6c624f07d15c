#pragma once
// What a training run tells its user and its log as it goes (trainRun's observer): the
// supervision and initialisation it starts with, the schedule, each step's events (drops,
// recovery, floaters, the Gaussian cap) and the progress line, and the summary at the end. The
// training loop itself says nothing.

#include <chrono>
#include <optional>
#include <ostream>
#include <string>

#include "sadsplat/gaussians/step_profile.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/scene.h"
#include "sadsplat/io/train_log.h"

namespace sadsplat {
namespace pipeline {

class TrainingReport {
 public:
  // `progress` (or none) gets the text; `log_path` (or "") the train log, continued after
  // `resumed_at` when resuming (-1: a new log).
  TrainingReport(std::ostream* progress, const std::string& log_path, int resumed_at);

  // The loop starts after iteration `first` (the progress line's rate counts from here).
  void begin(int first) {
    first_ = first;
    start_ = std::chrono::steady_clock::now();
  }
  // What supervises the run and where its Gaussians start (a new run only).
  void started(const io::Scene& scene, const gaussians::TrainConfig& config, bool resume);
  // The schedule as the trainer runs it.
  void schedule(const gaussians::TrainConfig& config);
  // Whether the model sat at max_gaussians already (a resumed run says the cap only once).
  void atCap(bool already) { said_cap_ = already; }
  // One step done: its events, the log records, the progress line.
  void stepped(const gaussians::StepStats& stats, const gaussians::TrainConfig& config,
               double seconds);
  // After the last step: steps rendered again, and the profile table (written by the caller).
  void finished(const gaussians::TrainConfig& config, const std::string& profile_table);

 private:
  void log(const gaussians::StepStats& s, double seconds, bool last);
  void events(const gaussians::StepStats& s, const gaussians::TrainConfig& config);
  void progressLine(const gaussians::StepStats& s, const gaussians::TrainConfig& config);

  std::ostream* progress_;
  std::optional<io::TrainLogWriter> log_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  int first_ = 0;  // the iteration before the first step of this process
  int rendered_again_ = 0;
  bool said_cap_ = false;
};

// "1m05s".
std::string formatSeconds(double seconds);

// Iterations between two reads of the loss values (train log records, progress line, the
// divergence check); the steps in between run without waiting for the device.
constexpr int kLossInterval = 10;

}  // namespace pipeline
}  // namespace sadsplat
