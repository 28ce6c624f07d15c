#pragma once
/// \file drop_strategy.h
/// \brief The hook through which the semantic-aware drop (module semantic_drop) acts on
/// training: gates on the opacities, a regularisation term, and drop decisions. The trainer works
/// without one (the paper's baseline, Net-1).

#include <ATen/ATen.h>

#include <array>
#include <cstdint>
#include <vector>

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace gaussians {

/// \brief What a drop strategy sees when it decides.
struct DropInputs {
  at::Tensor means;      ///< [N, 3]
  at::Tensor opacities;  ///< [N] activated
  at::Tensor log_alpha;  ///< [N]
  /// The training views with a confidence map: every view with pseudo-labels, and the labelled
  /// views (where their ground truth has a class the confidence is 1).
  std::vector<RasterCamera> cameras;
  std::vector<at::Tensor> confidence_maps;  ///< [H, W] max class confidence per pixel, per camera
  /// At most this many Gaussians go (those of highest P_drop first); -1: no cap.
  std::int64_t max_removed = -1;
};

/// \brief A drop decision and why Gaussians went.
struct DropDecision {
  at::Tensor keep;        ///< [N] bool
  at::Tensor confidence;  ///< [N] P_confidence (0 where the semantic term is off)
  at::Tensor p_drop;      ///< [N] the drop probability each Gaussian was drawn with
  std::int64_t removed = 0;
  std::int64_t removed_low_confidence = 0;  ///< of the removed: P_confidence < 0.5
  std::int64_t removed_closed_gate = 0;     ///< of the removed: P_nonzero < 0.5
  std::int64_t removed_unseen = 0;          ///< of the removed: centre in no confidence map
};

/// \brief The state of a drop rule's quality guard (DropStrategy::observeGuardReading), which
/// the trainer keeps and checkpoints for the strategy: the factor it leaves on the L0 strength and
/// the drop cap, the lowest probe reading since the last opacity reset (< 0: none yet) and the
/// iteration of the last reading.
struct DropGuard {
  double pressure = 1.0;
  double lowest = -1.0;
  double last_reading = 0.0;

  /// The checkpoint's form: the three values and kVersion (checkpoints written before the fixed
  /// probe views held a count of training-loss readings >= 0 there).
  static constexpr double kVersion = -2.0;
  std::array<double, 4> packed() const { return {pressure, lowest, last_reading, kVersion}; }
  /// From a checkpoint; one of another version keeps its pressure and starts a fresh reading.
  static DropGuard unpacked(const std::array<double, 4>& v) {
    if (v[3] != kVersion) return {v[0], -1.0, 0.0};
    return {v[0], v[1], v[2]};
  }
};

/// \brief The hook through which the semantic-aware drop (module semantic_drop) acts on
/// training; the trainer works without one (the baseline).
class DropStrategy {
 public:
  virtual ~DropStrategy() = default;
  /// \brief Factor on each Gaussian's opacity in the training render of `iteration`
  /// (undefined: none).
  virtual at::Tensor trainingGate(const at::Tensor& log_alpha, int iteration) const = 0;
  /// \brief Factor on each Gaussian's opacity when rendering for evaluation (undefined: none).
  virtual at::Tensor evaluationGate(const at::Tensor& log_alpha) const = 0;
  /// \brief Term added to the training loss of (0-based) `iteration` (undefined: none).
  /// \param[in] l0_weights [N] weight of each Gaussian in a sparsity term (undefined: equal;
  /// TrainConfig::l0_importance)
  virtual at::Tensor regularisation(const at::Tensor& log_alpha, int iteration,
                                    const at::Tensor& l0_weights) const = 0;
  /// \brief A force added to log_alpha's gradient after the backward pass (and the all-reduce)
  /// of (0-based) `iteration` instead of a loss term (the balanced rule; default: none).
  /// \param[in,out] grad [N] gradient of log_alpha
  /// \param[in] opacity_grad [N] gradient of the opacity logits (0: no loss reached the Gaussian)
  /// \param[in] l0_weights [N] weight of each Gaussian (undefined: equal)
  /// \param[in] guard the guard's state (its pressure scales the force)
  virtual void addL0Force(at::Tensor& grad, const at::Tensor& log_alpha,
                          const at::Tensor& opacity_grad, const at::Tensor& l0_weights,
                          int iteration, const DropGuard& guard) const {
    (void)grad, (void)log_alpha, (void)opacity_grad, (void)l0_weights, (void)iteration,
        (void)guard;
  }
  /// \brief Whether to drop once `iterations_done` iterations are done.
  virtual bool dropNow(int iterations_done) const = 0;
  /// \brief The most Gaussians the drop event may remove of `rows` (-1: no cap).
  virtual std::int64_t maxRemoved(std::int64_t rows, const DropGuard& guard) const {
    (void)rows, (void)guard;
    return -1;
  }
  /// \brief Whether the guard reads the model before the drop event after `iterations_done`
  /// (the trainer then renders its probe and hands the reading to observeGuardReading).
  virtual bool guardReadsBefore(int iterations_done) const {
    (void)iterations_done;
    return false;
  }
  /// \brief The guard's update from the reading before the event after `iterations_done`
  /// (the mean squared error of the fixed probe views rendered as for evaluation).
  virtual void observeGuardReading(DropGuard& guard, int iterations_done,
                                   double probe_mse) const {
    (void)guard, (void)iterations_done, (void)probe_mse;
  }
  /// \brief Which Gaussians to keep, their confidence and the reasons of the removals.
  virtual DropDecision decide(const DropInputs& inputs, int iterations_done) const = 0;
};

}  // namespace gaussians
}  // namespace sadsplat
