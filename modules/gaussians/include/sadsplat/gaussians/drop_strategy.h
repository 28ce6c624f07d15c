#pragma once
/// \file drop_strategy.h
/// \brief The hook through which the semantic-aware drop (module semantic_drop) acts on
/// training: gates on the opacities, a regularisation term, and drop decisions. The trainer works
/// without one (the paper's baseline, Net-1).

#include <ATen/ATen.h>

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
  /// \brief d P_nonzero / d log_alpha per Gaussian: the direction of the L0 force that the
  /// balanced rule scales (TrainConfig::drop_rule). Undefined: the strategy has no L0 term.
  virtual at::Tensor l0Derivative(const at::Tensor& log_alpha) const {
    (void)log_alpha;
    return {};
  }
  /// \brief Whether to drop once `iterations_done` iterations are done.
  virtual bool dropNow(int iterations_done) const = 0;
  /// \brief Which Gaussians to keep, their confidence and the reasons of the removals.
  virtual DropDecision decide(const DropInputs& inputs, int iterations_done) const = 0;
};

}  // namespace gaussians
}  // namespace sadsplat
