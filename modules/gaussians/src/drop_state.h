#pragma once
// The trainer's side of the semantic-aware drop: the strategy's gates over the schedule (training
// gate, evaluation gate, recovery phase), the per-Gaussian confidence and L0 weights that follow
// the rows, the drop events and the removal of closed gates.

#include <ATen/ATen.h>

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

class DropState {
 public:
  using Resize = DensificationStrategy::Resize;

  // The drop's own options; the schedule only for the run's length.
  DropState(const DropOptions& options, const ScheduleOptions& schedule)
      : options_(options), schedule_(schedule) {}
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
  // The strategy's loss term of `it` (undefined when not gated or none; the balanced rule has
  // none: its L0 force is added to the gradient by addL0Gradient instead).
  at::Tensor regularisation(const ParameterStore& params, int it) const;
  // The strategy's L0 force (DropStrategy::addL0Force; the balanced rule's), after the backward
  // (and the all-reduce) of iteration `it`.
  void addL0Gradient(ParameterStore& params, int it) const;
  // Whether the strategy's guard reads the model before the drop event after iteration `done`
  // (the trainer then hands the reading to observeGuardProbe).
  bool guardProbeDue(int done) const;
  // The reading before the event after iteration `done`: the mean squared error of the probe
  // views (guardProbeViews) rendered as evaluation renders them, so that two readings differ by
  // what training and dropping changed, not by which views the steps drew. The strategy updates
  // the guard kept here (DropStrategy::observeGuardReading).
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
  std::shared_ptr<const DropStrategy> drop_;
  at::Tensor confidence_;  // [N] last semantic confidence computed by the drop (0 before)
  at::Tensor l0_weights_;  // [N] weight of each Gaussian in the L0 term (l0_importance)
  DropGuard guard_;  // the strategy's guard, kept here for the checkpoint
};

}  // namespace gaussians
}  // namespace sadsplat
