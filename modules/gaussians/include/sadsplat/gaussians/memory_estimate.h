#pragma once
/// \file memory_estimate.h
/// \brief What a training run will hold on its device at its peak, estimated before it starts
/// from the scene and the configuration: what `train --blocks auto --max-gpu-memory` cuts a
/// survey by. Four parts:
/// - fixed: the CUDA context and LibTorch's kernels and workspaces (kFixedDeviceBytes; 0 for a
///   CPU device);
/// - views: the training views as the trainer keeps them (gaussians/src/training_views.h): held,
///   the picture (12 bytes a pixel), the mask (4), the supervising labels (8) and the drop's
///   confidence map (4) of every training view; streamed, only the confidence maps, plus one
///   view's pictures uploaded at a time per view a step renders;
/// - gaussians: the peak number of Gaussians (the starting points times
///   kPeakGaussiansPerPoint, at most max_gaussians) times what each holds: its learnable floats
///   (position, scales, rotation, opacity, SH, features, gate) four times (value, gradient, two
///   Adam moments), the render's per-Gaussian intermediates and their gradients, the
///   densification statistics and its share of the tile lists;
/// - render: one step's per-pixel buffers for each view it renders (colour, alpha, depth,
///   features and their gradients, the SSIM's blurred images) at the largest view's size.
/// The sum is multiplied by kAllocatorSlack (the caching allocator's rounding and fragments).
/// The constants were fitted on an H200 (docs/measurements/block_training): there the parts with
/// the Gaussian count a run reached came within 4 % of nvidia-smi's peak, and the estimate lies
/// 5-15 % above it. A planning number, not a bound: a scene that grows more Gaussians per point
/// than kPeakGaussiansPerPoint needs more.

#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace gaussians {

constexpr std::int64_t kFixedDeviceBytes = 768ll << 20;
/// The most Gaussians a default training reached per starting point: 3.6 on city-xxl (1,120
/// views of 1600x900, 320,000 points: 1,157,041), 3.8 on city-xl (Net-1).
constexpr double kPeakGaussiansPerPoint = 4.0;
constexpr double kAllocatorSlack = 1.05;

/// \brief A training run's estimated peak device memory, by part (bytes).
struct MemoryEstimate {
  std::int64_t fixed = 0;
  std::int64_t views = 0;
  std::int64_t gaussians = 0;
  std::int64_t render = 0;
  std::int64_t peak_gaussians = 0;  ///< the Gaussian count `gaussians` was estimated for
  /// (fixed + views + gaussians + render) x kAllocatorSlack
  std::int64_t total() const;
  /// \brief "X GiB estimated (views a, N Gaussians at the peak b, render c, fixed d)"
  std::string describe() const;
};

/// \brief Bytes one Gaussian takes on the device during training with `config`.
std::int64_t bytesPerGaussian(const TrainConfig& config);

/// \brief The estimate for training `views` (indices into scene.views, training views) from
/// `points` starting points with `config` (stream_views, feature_dim, max_sh_degree,
/// views_per_step, max_gaussians, use_pseudo_labels are read).
MemoryEstimate estimateTrainingMemory(const io::Scene& scene, const std::vector<int>& views,
                                      std::size_t points, const TrainConfig& config);

/// \brief The same for the whole scene: its training views and its sparse points (or
/// init_random_count when it starts from random points).
MemoryEstimate estimateTrainingMemory(const io::Scene& scene, const TrainConfig& config);

}  // namespace gaussians
}  // namespace sadsplat
