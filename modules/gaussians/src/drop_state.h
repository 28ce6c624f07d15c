#pragma once
// The trainer's side of the semantic-aware drop: the strategy's gates over the schedule (training
// gate, evaluation gate, recovery phase), the per-Gaussian confidence and L0 weights that follow
// the rows, the drop events and the removal of closed gates.

#include <ATen/ATen.h>

#include <array>
#include <cstdint>
#include <memory>
#include <utility>

#include "sadsplat/gaussians/densification.h"
#include "sadsplat/gaussians/drop_strategy.h"
#include "sadsplat/gaussians/parameter_store.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/train_config.h"
#include "training_views.h"

namespace sadsplat {
namespace gaussians {

// The balanced rule's guard (DropState::observeGuardProbe): the factor it leaves on the L0
// strength and the drop cap, the lowest probe reading since the last opacity reset (< 0: none
// yet) and the iteration of the last reading.
struct DropGuard {
  double pressure = 1.0;
  double lowest = -1.0;
  double last_reading = 0.0;

  // The checkpoint's form: the three values and kVersion (checkpoints written before the fixed
  // probe views held a count of training-loss readings >= 0 there).
  static constexpr double kVersion = -2.0;
  std::array<double, 4> packed() const { return {pressure, lowest, last_reading, kVersion}; }
  // From a checkpoint; one of another version keeps its pressure and starts a fresh reading.
  static DropGuard unpacked(const std::array<double, 4>& v) {
    if (v[3] != kVersion) return {v[0], -1.0, 0.0};
    return {v[0], v[1], v[2]};
  }
};

class DropState {
 public:
  using Resize = DensificationStrategy::Resize;

  // The drop's own options; the schedule and the densification's only for the run's length and
  // its opacity resets (the guard's reference starts afresh after one).
  DropState(const DropOptions& options, const ScheduleOptions& schedule,
            const DensificationOptions& densification)
      : options_(options), schedule_(schedule), densification_(densification) {}
  void setStrategy(std::shared_ptr<const DropStrategy> strategy) { drop_ = std::move(strategy); }
  void initialise(std::int64_t rows, const at::TensorOptions& options);

  // The first iteration of the recovery phase (TrainConfig::recovery_iterations): from there on
  // no gates, no L0 term and no drops. Past the end without a drop or a recovery.
  int recoveryStart() const;
  // Whether (0-based) iteration `it` trains with the drop's gates.
  bool gated(int it) const { return drop_ && it < recoveryStart(); }

  // The deterministic (evaluation) gate per Gaussian at `iteration`; undefined without a drop,
  // and once the gates are folded into the opacities.
  at::Tensor evaluationGate(const ParameterStore& params, int iteration) const;
  // The sampled gate of the training render of `it` (undefined when not gated).
  at::Tensor trainingGate(const ParameterStore& params, int it) const;
  // Activated opacity times the evaluation gate (when there is one).
  at::Tensor effectiveOpacity(const ParameterStore& params, int iteration) const;
  // The strategy's loss term of `it` (undefined when not gated or none, and under the balanced
  // rule, whose L0 force is added to the gradient by addL0Gradient instead).
  at::Tensor regularisation(const ParameterStore& params, int it) const;
  // The balanced rule's L0 force (TrainConfig::drop_rule), after the backward (and the
  // all-reduce) of iteration `it`: on each Gaussian the losses reached (its opacity has a
  // gradient), l0_strength x pressure x (the mean |log_alpha gradient| over those Gaussians) x
  // dP_nonzero / (the mean dP_nonzero over them).
  void addL0Gradient(ParameterStore& params, int it) const;
  // The balanced rule's guard reads the model before each of its drop events: whether the event
  // after iteration `done` wants a reading (the trainer then hands it to observeGuardProbe).
  bool guardProbeDue(int done) const;
  // The reading before the event after iteration `done`: the mean squared error of the probe
  // views (guardProbeViews) rendered as evaluation renders them, so that two readings differ by
  // what training and dropping changed, not by which views the steps drew. A reading more than
  // drop_guard above the lowest since the last opacity reset (a reset raises the error by
  // itself) halves the pressure.
  void observeGuardProbe(int done, double probe_mse);
  // The factor on the L0 strength and the drop cap that the guard has left (1 at the start).
  double pressure() const { return guard_.pressure; }

  // Whether the L0 term's weights are recomputed before iteration `it`: with l0_importance, when
  // the L0 schedule starts and every drop interval after (a fixed schedule, so that a resumed run
  // recomputes them where an uninterrupted one does; between, they follow the Gaussians' rows).
  bool refreshesL0Weights(int it) const;
  // The L0 weights from each Gaussian's contribution to the training views as rendered for
  // evaluation (opacity x deterministic gate).
  void refreshL0Weights(const ParameterStore& params, const TrainingViews& views, int iteration);

  // After iteration `done` of a gated step: a drop event if the strategy wants one. Returns the
  // decision (tensors undefined if none) and sets `dropped`.
  DropDecision dropIfDue(int done, const ParameterStore& params, const TrainingViews& views,
                         const Resize& resize, std::int64_t* dropped);
  // Start of the recovery phase: with a drop, the Gaussians with a closed gate go and the other
  // gates are folded into the opacities (their log_alpha fixed open); then, with recovery_prune,
  // the share of Gaussians that contribute least to the training views goes. Returns
  // {closed, pruned}.
  std::pair<std::int64_t, std::int64_t> settleGates(ParameterStore& params,
                                                    const TrainingViews& views,
                                                    const Resize& resize);
  // After the last iteration: Gaussians whose evaluation gate is closed (z = 0) render nothing;
  // removing them changes no render. Returns how many went.
  std::int64_t removeClosedGates(const ParameterStore& params, int iteration, const Resize& resize);

  const at::Tensor& confidence() const { return confidence_; }
  void resized(const RowChange& change);
  void save(TensorArchive& archive) const;
  void load(const TensorArchive& archive, const std::string& path, const at::Device& device);
  void checkRows(std::int64_t rows) const;
  /// The archive names (save) of the per-row tensors.
  std::vector<std::string> rowTensors() const { return {"confidence", "l0_weights"}; }

 private:
  DropOptions options_;
  ScheduleOptions schedule_;
  DensificationOptions densification_;
  std::shared_ptr<const DropStrategy> drop_;
  at::Tensor confidence_;  // [N] last semantic confidence computed by the drop (0 before)
  at::Tensor l0_weights_;  // [N] weight of each Gaussian in the L0 term (l0_importance)
  bool balanced() const { return balancedDropRule(options_); }
  bool openedByReset(int from, int to) const;
  DropGuard guard_;
};

}  // namespace gaussians
}  // namespace sadsplat
