#pragma once
/// \file trainer.h
/// \brief The semantic Gaussian trainer (Feature-3DGS style, the paper's baseline "Net-1"):
/// 3DGS optimisation (Adam, exponential position learning rate, SH schedule, densification,
/// opacity reset) + a per-Gaussian semantic feature decoded by a learned 1x1 layer and
/// supervised with a masked cosine loss on the labelled views.

#include <ATen/ATen.h>
#include <pcl/point_cloud.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/gaussians/collective.h"
#include "sadsplat/gaussians/drop_strategy.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/step_profile.h"
#include "sadsplat/gaussians/surface_layer.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace gaussians {

/// \brief Numbers reported after each step.
struct StepStats {
  int iteration = 0;
  /// Whether the loss values below were read (step(true)); after step(false) they are NaN.
  bool losses_read = true;
  double loss = 0, rgb_loss = 0, semantic_loss = 0;
  std::int64_t num_gaussians = 0;
  std::int64_t dropped = 0;  ///< Gaussians removed by the drop in this step
  DropDecision drop;         ///< the decision behind `dropped` (tensors undefined if none)
  double drop_pressure = 1;  ///< the balanced rule's factor on L0 strength and cap (guard)
  /// After the last iteration: Gaussians removed because their evaluation gate is closed (z = 0,
  /// they render nothing).
  std::int64_t removed_closed_gates = 0;
  /// After the last iteration, with TrainConfig::prune_floaters: the floaters removed.
  std::int64_t removed_floaters = 0;
  /// Whether the recovery phase (TrainConfig::recovery_iterations) starts after this step; if so
  /// the Gaussians removed then for a closed gate, and for their small contribution.
  bool recovery_started = false;
  std::int64_t recovery_closed_gates = 0;
  std::int64_t recovery_pruned = 0;
  int pseudo_labelled_views = 0;  ///< training views supervised by pseudo-labels
  /// CUDA: a render's tile list, sized from earlier counts, was short, so the step rendered its
  /// views again with exact lists (TrainConfig::tile_list_margin).
  bool rendered_again = false;
};

/// \brief What a Trainer holds of its scene's views: everything a training needs, or only the
/// cameras (a trainer that renders a trained model).
enum class TrainerViews { kLoaded, kCamerasOnly };

/// \brief The surface a Gaussian's gap is measured against (Trainer::renderedDepthResiduals).
enum class SurfaceDepth {
  /// The expected depth (renderDepth's alpha-weighted mean) over every pixel the Gaussian
  /// draws: contribution.h's depthResiduals. Keeps more of the roofs that oblique photos see at
  /// their silhouettes; the map products (`ortho --on-surface`) use it.
  kExpected,
  /// The median depth (where the transmittance falls below 0.5) over the pixels where the
  /// Gaussian is composited before it (seen, not hidden): surface_layer.h's surfaceGapSums, one
  /// CPU compositing pass per camera. More of the kept cloud lies on a true surface; the cloud
  /// (`extract --on-surface`, `eval --3d`) uses it.
  kMedianWhereSeen,
};

/// \brief Trains Gaussians on a scene.
///
/// Randomness (view order, split samples, feature initialisation) is derived from the seed and
/// the iteration, so a run resumed from a checkpoint continues exactly as it would have.
class Trainer {
 public:
  /// \param[in] scene an imported scene with sparse points and at least one training view
  /// \param[in] config the configuration (validated)
  /// \param[in] views kLoaded: the training views are read and held (or streamed) for step();
  /// kCamerasOnly: only the cameras, for rendering a trained model (loadCheckpoint): no view's
  /// pixels read or held, and step() is an error
  /// \throws sadsplat::Error on an unusable scene or configuration
  Trainer(const io::Scene& scene, const TrainConfig& config,
          TrainerViews views = TrainerViews::kLoaded);
  ~Trainer();
  Trainer(const Trainer&) = delete;
  Trainer& operator=(const Trainer&) = delete;

  /// \brief Installs the semantic-aware drop (none by default).
  void setDropStrategy(std::shared_ptr<const DropStrategy> strategy);
  /// \brief Trains as one rank of a data-parallel group: each rank renders its own views, the
  /// gradients and densification statistics are summed over the ranks, so every rank keeps the
  /// same Gaussians. Set before the first step (null: a single process).
  void setCollective(Collective::Ptr collective);
  /// \brief Times the phases of every following step() in `profile` (null: stop timing).
  void setProfile(StepProfile::Ptr profile);

  /// \brief One optimisation step (render, loss, backward, Adam, densification schedule). With a
  /// drop strategy, densification prunes by the opacity a Gaussian renders with at evaluation
  /// (opacity x deterministic gate), and the last step removes the Gaussians whose gate is closed;
  /// with TrainConfig::recovery_iterations the gates end earlier (see there).
  /// \param[in] read_losses whether to copy the step's loss values to the host. Reading them waits
  /// for the device to finish the step; without it (false) a GPU step returns as soon as its work
  /// is queued, so the host prepares the next step while the device runs this one. Every rank of
  /// a group must pass the same value.
  StepStats step(bool read_losses = true);
  /// \brief Iterations done so far.
  int iteration() const;
  const TrainConfig& config() const;

  /// \brief Renders a view of the scene with the current Gaussians (no gradients).
  RenderResult renderView(const io::View& view) const;
  /// \brief Renders the current Gaussians through any camera (no gradients): other sizes,
  /// novel views, the orthographic map camera. As renderView for a view's own camera.
  RenderResult renderCamera(const RasterCamera& camera) const;
  /// \brief As renderCamera, drawing only the Gaussians where `keep` ([N] bool, on any device) is
  /// true (a viewer's class selection); an undefined `keep` draws them all.
  RenderResult renderCamera(const RasterCamera& camera, const at::Tensor& keep) const;
  /// \brief As renderCamera, each Gaussian carrying its row of `features` ([N, C], any device)
  /// in place of its semantic feature: RenderResult::features composites them (one-hot classes
  /// give each class's blending weight over each pixel). `keep` as renderCamera's.
  /// \throws sadsplat::Error when `features` is not one row per Gaussian
  RenderResult renderCameraWith(const RasterCamera& camera, const at::Tensor& features,
                                const at::Tensor& keep = at::Tensor()) const;
  /// \brief As renderCamera, without the features: colour, alpha and expected depth; `keep` as
  /// there.
  RenderResult renderDepth(const RasterCamera& camera, const at::Tensor& keep = at::Tensor()) const;
  /// \brief Per-pixel class ids [H, W] int64 from a render's feature image (argmax of the cosine
  /// similarity of the decoded feature to each class embedding).
  at::Tensor predictClasses(const RenderResult& render) const;
  /// \brief Per-pixel cosine similarity of the decoded feature to each class's one-hot
  /// embedding [H, W, classes]: what the semantic loss trains (1 - cosine), so its maximum is at
  /// predictClasses' class and is that class's confidence (1: the decoded feature is exactly the
  /// class's embedding; near 1/sqrt(classes): no class stands out). Not a calibrated
  /// probability. Undefined tensor when the model has no classes.
  at::Tensor classCosines(const RenderResult& render) const;
  /// \brief The same for any feature image [H, W, C] (e.g. SurfaceLayer::features), on the
  /// device of the model.
  at::Tensor classCosines(const at::Tensor& features) const;
  /// \brief The first surface of the current Gaussians through a camera: where
  /// the transmittance falls below `level` (surface_layer.h), the Gaussians as renderCamera
  /// draws them. On the CPU. `features` false: SurfaceLayer::features has 0 channels (the
  /// compositing skips them). `keep` as renderCamera's.
  SurfaceLayer renderSurface(const RasterCamera& camera, double level = 0.5, bool features = true,
                             const at::Tensor& keep = at::Tensor()) const;
  /// \brief Per Gaussian and class [N, classes] (float, on the CPU): its blending weight summed
  /// over the pixels that this model's render of each camera shows as that class
  /// (contribution.h's classWeightSums with predictClasses' maps): what the views say each
  /// Gaussian is. Each camera is rendered twice.
  /// \throws sadsplat::Error when the model has no classes
  at::Tensor renderedClassWeights(const std::vector<RasterCamera>& cameras) const;
  /// \brief Per Gaussian [N] (float, on the CPU): the gap between its centre and the surface this
  /// model renders through each camera, in scene units; +inf where no camera shows it on a
  /// surface. `against` says which surface and over which pixels (SurfaceDepth).
  at::Tensor renderedDepthResiduals(const std::vector<RasterCamera>& cameras,
                                    SurfaceDepth against) const;
  /// \brief Classes the model decodes (0: a plain 3DGS model).
  int numClasses() const;

  /// \brief The Gaussians as a PCL cloud; label = class of the decoded feature of each Gaussian,
  /// log_alpha / confidence as stored.
  pcl::PointCloud<GaussianPoint> toCloud() const;
  std::int64_t numGaussians() const;
  /// \brief [N] the opacity each Gaussian renders with at evaluation: sigmoid of its logit, times
  /// the drop's deterministic gate while gates are on.
  at::Tensor effectiveOpacity() const;
  /// \brief Replaces the Gaussians by `cloud` (its features in this model's feature space, e.g.
  /// merges of this model's Gaussians): parameters from the cloud, their Adam moments and every
  /// per-Gaussian statistic restarted at zero; the decoder, the drop's guard and the iteration
  /// stay. For evaluating a simplified model with this run's decoder (`sadsplat compact`).
  /// \throws sadsplat::Error for an empty cloud
  void setGaussians(const pcl::PointCloud<GaussianPoint>& cloud);

  /// \brief Every tensor of the training state, copied to host memory: the archive stays as it
  /// is while training goes on (for writing it on another thread).
  TensorArchive checkpointSnapshot() const;
  /// \brief Writes every tensor of the training state (atomically).
  void saveCheckpoint(const std::string& path) const;
  /// \brief Restores a state written by saveCheckpoint (same scene and configuration).
  void loadCheckpoint(const std::string& path);
  /// \brief Restores a state from an archive (as loadCheckpoint; `path` names it in errors).
  void loadCheckpoint(const TensorArchive& archive, const std::string& path);
  /// \brief The names of the checkpoint's tensors with one row per Gaussian (parameters and
  /// their Adam moments, the drop's and the densification's statistics); the others are global
  /// (the decoder, the drop's guard).
  std::vector<std::string> checkpointRowTensors() const;

  /// \brief Render-ready parameters (for tests): activated views are not applied.
  GaussianParams parameters() const;
  /// \brief Extra state consistency check (sizes of parameters, optimiser state, statistics).
  /// \throws sadsplat::Error describing the first inconsistency
  void checkConsistency() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace gaussians
}  // namespace sadsplat
