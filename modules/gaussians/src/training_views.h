#pragma once
// The scene's views as the trainer uses them: images, masks, semantic supervision and the drop's
// confidence maps on the device, and the cameras.

#include <ATen/ATen.h>

#include <memory>
#include <vector>

#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/gaussians/view_coverage.h"
#include "sadsplat/io/scene.h"
#include "view_loader.h"

namespace sadsplat {
namespace gaussians {

// What a view trains besides the picture: the features (it has a semantic loss) and the decoder
// (the loss also trains it).
struct ViewRole {
  bool semantic = false;
  bool decoder_learns = false;
};

constexpr int kGuardProbeViews = 4;

// A training view's pictures on the device, as the losses read them.
struct DeviceView {
  at::Tensor image;   // [H, W, 3] float in [0, 1]
  at::Tensor mask;    // [H, W] float, 1 = valid pixel
  at::Tensor labels;  // [H, W] int64, -1 = not supervised (or undefined)
};

// How many steps ahead the loader reads the views of a scene read without pixels.
constexpr int kPrefetchSteps = 16;

struct TrainingViews {
  // Held (the default): images, masks and labels are the DeviceView tensors, on the device.
  // Streamed (TrainConfig::stream_views): they are host copies in 8 / 8 / 16 bits (pinned for a
  // CUDA device) that onDevice uploads and converts each time a step uses the view. Streamed
  // from a scene read without pixels (io::readSceneCacheWithoutPixels): `loader` reads them from
  // the cache ahead of the steps (prefetch) and images / masks / labels stay undefined.
  bool streamed = false;
  // Only the cameras (cameraViews): a trainer that renders a trained model, never trains.
  bool cameras_only = false;
  std::shared_ptr<ViewLoader> loader;
  int prefetched_until = -1;  // the last step whose views the loader was asked for
  at::Device device{at::kCPU};
  std::vector<RasterCamera> cameras;  // every view of the scene
  std::vector<at::Tensor> images;     // training views only (see above)
  std::vector<at::Tensor> masks;
  std::vector<char> mask_is_full;           // every pixel valid: the mask multiplies nothing
  std::vector<at::Tensor> labels;           // undefined where a view supervises no class
  std::vector<char> supervised;             // some pixel of the view has a class to learn
  std::vector<double> semantic_weight;      // lambda_semantic (ground truth) or lambda_pseudo
  std::vector<at::Tensor> confidence_maps;  // [H, W] max class confidence (or undefined)
  // The scene's sparse points each training view sees (on the device; empty for every view when
  // the sparse-depth loss is off or the scene has no points).
  std::vector<SparseDepthSamples> sparse_depths;
  int pseudo_labelled_views = 0;
  std::vector<int> train_views, labelled_views;

  // View v's pictures on the device: the held tensors, or the host copies uploaded (the copy is
  // queued on the current stream: the host does not wait for it).
  DeviceView onDevice(int v) const;
  std::vector<RasterCamera> trainingCameras() const;
  // Asks the loader (if any) for the views of steps `it` .. it + kPrefetchSteps and forgets
  // those of earlier steps.
  void prefetch(const TrainConfig& config, int it, int rank, int ranks);
  // The training views the drop's guard renders (a fixed set, so its readings are comparable):
  // up to kGuardProbeViews spread evenly over the training views.
  std::vector<int> guardProbeViews() const;
  ViewRole role(int v, const TrainConfig& config) const;
};

// The views one rank renders in one step, and what the whole group's views train.
struct StepViews {
  std::vector<int> views;
  bool features_anywhere = false;  // some rank's views train the features (groups only)
  bool decoder_anywhere = false;   // some rank's views train the decoder (groups only)
};

// Iteration `it`'s views: the next training view of a seeded shuffle, and every
// semantic_interval iterations the next labelled view. Data-parallel ranks split one global
// batch of views_per_step x ranks draws: this rank's draws are numbered
// rank * views_per_step + b, so N ranks draw what one process with N times the views would.
// `in_group`: also say what the whole group's views train (a group of one included).
StepViews drawStepViews(const TrainingViews& views, const TrainConfig& config, int it, int rank,
                        int ranks, bool in_group);

/// The cameras of `scene`'s views and which views train, no picture read: for a trainer that
/// only renders (TrainerViews::kCamerasOnly).
/// \throws sadsplat::Error when the scene has no training view
TrainingViews cameraViews(const io::Scene& scene, const at::Device& device);

/// Loads the views of `scene` onto `device`.
/// \throws sadsplat::Error when the scene has no training view
TrainingViews loadTrainingViews(const io::Scene& scene, const TrainConfig& config,
                                const at::Device& device);

// The sparse points of `scene` that each training view of `views` sees (visibleSparseDepths),
// on the views' device, into views.sparse_depths; returns how many samples all views hold.
std::int64_t addSparseDepths(const io::Scene& scene, TrainingViews& views);

}  // namespace gaussians
}  // namespace sadsplat
