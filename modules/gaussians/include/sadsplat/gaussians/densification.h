#pragma once
/// \file densification.h
/// \brief How the Gaussian set grows and shrinks during training, as a replaceable strategy
/// with hooks around the optimiser step (gsplat's `strategy/` is the model): the default is the
/// 3D Gaussian Splatting one (clone small and split large Gaussians with a large screen-space
/// gradient, prune transparent and huge ones, reset opacities).

#include <ATen/ATen.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sadsplat/gaussians/collective.h"
#include "sadsplat/gaussians/parameter_store.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/train_config.h"

namespace sadsplat {
namespace gaussians {

/// \brief A densification strategy: statistics over the steps, and the edits they lead to.
class DensificationStrategy {
 public:
  using Ptr = std::shared_ptr<DensificationStrategy>;
  virtual ~DensificationStrategy() = default;

  /// \brief Starts with `rows` Gaussians (statistics at zero).
  virtual void initialise(std::int64_t rows, const at::TensorOptions& options) = 0;
  /// \brief After backward: the renders of this step's views (their means2d gradients and radii)
  /// with the cameras and the global batch size. With a collective, the step's sums are kept
  /// apart and returned, to be all-reduced with the gradients; then reduced() adds them.
  virtual std::vector<at::Tensor*> stepPostBackward(const std::vector<RenderResult>& renders,
                                                    const std::vector<RasterCamera>& cameras,
                                                    int batch, Collective* collective) = 0;
  /// \brief With a collective, after the all-reduce of the returned sums.
  virtual void reduced(Collective& collective) = 0;
  /// \brief Resizes the Gaussians: keeps the rows where `keep` is true, appends `extra` rows
  /// (per parameter name), and keeps every other per-row state in step (the trainer's).
  using Resize =
      std::function<void(const at::Tensor& keep, const std::map<std::string, at::Tensor>& extra)>;
  /// \brief After the optimiser step of iteration `done` (1-based): grows and prunes through
  /// `resize`, edits `params` in place (opacity reset).
  /// \param[in] effective_opacity gives the [N] opacity as rendered for evaluation (with the
  /// drop's gate), asked for only when pruning
  virtual void stepPostUpdate(int done, ParameterStore& params,
                              const std::function<at::Tensor()>& effective_opacity,
                              const Resize& resize) = 0;
  /// \brief Keeps the statistics in step with a resize of the Gaussians.
  virtual void resized(const RowChange& change) = 0;
  virtual void save(TensorArchive& archive) const = 0;
  virtual void load(const TensorArchive& archive, const std::string& path,
                    const at::Device& device) = 0;
  /// \brief Throws unless every statistic has `rows` rows.
  virtual void checkRows(std::int64_t rows) const = 0;
  /// \brief The archive names (save) of the statistics with one row per Gaussian.
  virtual std::vector<std::string> rowTensors() const = 0;
};

/// \brief The 3DGS strategy with its options (densify_* / percent_dense / min_opacity /
/// opacity_reset_interval / max_screen_radius / max_gaussians / large splits) in the run's
/// `schedule` (iterations, seed); `extent` is the scene's.
DensificationStrategy::Ptr makeDefaultDensification(const DensificationOptions& options,
                                                    const ScheduleOptions& schedule, double extent);

/// \brief Whether the default strategy resets the opacities after iteration `done`: a multiple of
/// opacity_reset_interval up to densify_until (resolved, not -1), and none in the last third of
/// an interval before the end of the run (the opacities would have no time to recover).
bool resetsOpacitiesAfter(const DensificationOptions& options, const ScheduleOptions& schedule,
                          int done);
/// \brief resetsOpacitiesAfter for a whole configuration.
inline bool resetsOpacitiesAfter(const TrainConfig& config, int done) {
  return resetsOpacitiesAfter(config, config, done);
}

/// \brief One line of what the default strategy does over the run of `config` (densify_until
/// and scale_limit_from resolved, not -1), e.g. "7000 iterations; densification after 500
/// until 2000 every 100; opacity reset none; scale limit 0.1 x the extent from 6000".
std::string describeDefaultDensification(const TrainConfig& config);

}  // namespace gaussians
}  // namespace sadsplat
