#pragma once
/// \file step_profile.h
/// \brief Where the time of training steps goes (`sadsplat train --profile`): wall time per
/// named phase, summed over iterations. Each phase waits for the device before its clock starts
/// and before it stops, so on a GPU the split is exact but the run is slower than an unprofiled
/// one (the CPU can no longer queue work ahead of the GPU); compare the total with an unprofiled
/// run to see what the synchronisation itself costs.

#include <ATen/ATen.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

namespace sadsplat {
namespace gaussians {

/// \brief Blocks until every kernel queued on `device` has finished (no-op on the CPU).
void synchronizeDevice(const at::Device& device);

/// \brief Accumulated wall time per phase of training steps. One phase runs at a time:
/// enter() ends the current phase and starts the next, leave() ends it.
class StepProfile {
 public:
  using Ptr = std::shared_ptr<StepProfile>;

  /// \param[in] device the device whose queue each phase boundary waits for
  explicit StepProfile(const at::Device& device);

  /// \brief Ends the current phase (if any) and starts `name` (phases appear in the table in
  /// first-use order).
  void enter(const std::string& name);
  /// \brief Ends the current phase (if any).
  void leave();
  /// \brief Counts one iteration (the table's per-iteration column divides by this).
  void countIteration() { ++iterations_; }
  int iterations() const { return iterations_; }
  /// \brief Total seconds spent in `name` so far (0 for a phase never timed).
  double seconds(const std::string& name) const;
  /// \brief Total seconds of all phases.
  double totalSeconds() const;
  /// \brief A Markdown table: phase, total seconds, milliseconds per iteration, share.
  std::string table() const;

 private:
  at::Device device_;
  std::vector<std::string> names_;
  std::vector<double> seconds_;
  int current_ = -1;
  std::chrono::steady_clock::time_point start_;
  int iterations_ = 0;
};

/// \brief profile->enter(name), or nothing when `profile` is null.
inline void enterPhase(StepProfile* profile, const std::string& name) {
  if (profile != nullptr) profile->enter(name);
}

}  // namespace gaussians
}  // namespace sadsplat
