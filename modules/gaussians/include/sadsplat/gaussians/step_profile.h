#pragma once
/// \file step_profile.h
/// \brief Where the time of training steps goes (`sadsplat train --profile`): wall time per
/// named phase, summed over iterations. Each phase waits for the device before its clock starts
/// and before it stops, so on a GPU the split is exact but the run is slower than an unprofiled
/// one (the CPU can no longer queue work ahead of the GPU); compare the total with an unprofiled
/// run to see what the synchronisation itself costs.
///
/// On the host's clock (`sadsplat train --profile-host`) no phase waits for the device: a phase
/// gets the time the CPU spent issuing its work, and a phase that has to read a device value
/// (the binning's intersection count) shows the wait for the GPU's queue. When the phases' host
/// time adds up to the unprofiled run's wall time, the host, not the GPU, sets the pace.
/// Either way each phase also counts the ATen operator calls it made (each costs host time in
/// the dispatcher, and on a GPU usually one kernel launch).
///
/// Phases nest: library code deeper down (the rasterizer's steps, the SSIM) opens a
/// ScopedPhase, which the active profile (setActiveProfile / ActiveProfileScope) records as
/// "parent / name". A phase's time is its own (exclusive): the time of the phases nested in it
/// is not counted twice, so the phases still add up to the total. On a CUDA device each phase
/// also records the largest amount of device memory allocated while it ran.

#include <ATen/ATen.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace sadsplat {
namespace gaussians {

/// \brief Blocks until every kernel queued on `device` has finished (no-op on the CPU).
void synchronizeDevice(const at::Device& device);

/// \brief Accumulated wall time (and, on CUDA, peak device memory) per phase of training steps.
/// enter() ends the current phase and starts the next at the top level, push() opens a phase
/// nested in the current one, pop() closes it, leave() closes all.
class StepProfile {
 public:
  using Ptr = std::shared_ptr<StepProfile>;

  /// \brief Which clock the phases run on.
  enum class Clock {
    kDeviceWaited,  ///< each boundary waits for the device: a phase gets its device work's time
    kHost,          ///< no waits: a phase gets the host's time (see the file comment)
  };

  /// \param[in] device the device whose queue each phase boundary waits for (kDeviceWaited); on
  /// CUDA the device's memory peaks so far are kept as those "before the first phase"
  explicit StepProfile(const at::Device& device, Clock clock = Clock::kDeviceWaited);
  ~StepProfile();
  StepProfile(const StepProfile&) = delete;
  StepProfile& operator=(const StepProfile&) = delete;

  /// \brief Ends the current phases (if any) and starts the top-level phase `name` (phases
  /// appear in the table in first-use order).
  void enter(const std::string& name);
  /// \brief Ends every open phase.
  void leave();
  /// \brief Opens "<current phase> / name" nested in the current phase (or the top-level phase
  /// `name` when none is open); the current phase's clock pauses until pop().
  void push(const std::string& name);
  /// \brief Closes the innermost phase; its parent's clock runs again.
  void pop();
  /// \brief Whether a phase is open.
  bool inPhase() const { return !stack_.empty(); }
  /// \brief Counts one iteration (the table's per-iteration column divides by this).
  void countIteration() { ++iterations_; }
  int iterations() const { return iterations_; }
  /// \brief Total seconds spent in `name` itself so far, nested phases excluded (0 for a phase
  /// never timed). Nested phases are named "parent / child".
  double seconds(const std::string& name) const;
  /// \brief Total seconds of all phases.
  double totalSeconds() const;
  /// \brief The largest device memory allocated while `name` ran (bytes; 0 on the CPU).
  std::int64_t peakAllocatedBytes(const std::string& name) const;
  /// \brief ATen operator calls (nested ones included) made while `name` was the innermost
  /// open phase, from any thread (the autograd engine's too).
  std::int64_t operatorCalls(const std::string& name) const;
  /// \brief A Markdown table: phase, total seconds, milliseconds per iteration, share, operator
  /// calls per iteration (and on CUDA with device waits the peak allocated MiB per phase, and
  /// the peaks of the whole run).
  std::string table() const;
  /// \brief Per phase, the ATen operators it called (by name, nested calls included, the
  /// autograd engine's evaluate_function entries too) with their calls per iteration, most
  /// first, those of at least `min_per_iteration`: a Markdown list. Where the host's time of a
  /// phase goes, operator by operator.
  std::string operatorTable(double min_per_iteration = 0.05) const;

 private:
  friend struct OperatorCallObserver;  // step_profile.cpp: records each call's name
  void recordOperator(const char* name);
  struct Phase {
    std::string name;
    double seconds = 0.0;
    std::int64_t peak_allocated = 0;
    std::int64_t operator_calls = 0;
  };
  const Phase* find(const std::string& name) const;  // null when never timed
  bool waitsForDevice() const;
  int indexOf(const std::string& name);  // find(), or a new phase
  void closeSlice();  // (waits for the device,) credits the innermost phase with its time
  void openSlice();   // starts the clock (and the device's peak memory counters) afresh

  at::Device device_;
  Clock clock_;
  std::int64_t calls_at_open_ = 0;  // the process's operator-call count when the slice opened
  std::vector<Phase> phases_;
  std::vector<int> stack_;
  std::chrono::steady_clock::time_point start_;
  int iterations_ = 0;
  std::int64_t peak_reserved_ = 0;
  // The device's peaks before this profile existed (scene loading, initialisation).
  std::int64_t peak_allocated_before_ = 0, peak_reserved_before_ = 0;
  // The innermost open phase (-1: none) as the observer (any thread) reads it, and per phase
  // the calls of each operator name.
  std::atomic<int> open_phase_{-1};
  mutable std::mutex names_mutex_;
  std::vector<std::map<std::string, std::int64_t>> operator_names_;
};

/// \brief profile->enter(name), or nothing when `profile` is null.
inline void enterPhase(StepProfile* profile, const std::string& name) {
  if (profile != nullptr) profile->enter(name);
}

/// \brief The profile that ScopedPhase reports to (process-wide: the autograd engine runs CUDA
/// backward passes in its own thread); null when none.
StepProfile* activeProfile();
/// \brief Makes `profile` (may be null) the active one.
void setActiveProfile(StepProfile* profile);

/// \brief Makes a profile active for a scope and restores the previous one after it.
class ActiveProfileScope {
 public:
  explicit ActiveProfileScope(StepProfile* profile) : previous_(activeProfile()) {
    setActiveProfile(profile);
  }
  ~ActiveProfileScope() { setActiveProfile(previous_); }
  ActiveProfileScope(const ActiveProfileScope&) = delete;
  ActiveProfileScope& operator=(const ActiveProfileScope&) = delete;

 private:
  StepProfile* previous_;
};

/// \brief A nested phase of the active profile for the lifetime of this object; nothing when no
/// profile is active or it has no open phase.
class ScopedPhase {
 public:
  explicit ScopedPhase(const char* name) : profile_(activeProfile()) {
    if (profile_ != nullptr && profile_->inPhase()) {
      profile_->push(name);
    } else {
      profile_ = nullptr;
    }
  }
  ~ScopedPhase() {
    if (profile_ != nullptr) profile_->pop();
  }
  ScopedPhase(const ScopedPhase&) = delete;
  ScopedPhase& operator=(const ScopedPhase&) = delete;

 private:
  StepProfile* profile_;
};

}  // namespace gaussians
}  // namespace sadsplat
