#pragma once
/// \file train_config.h
/// \brief The trainer's configuration and its JSON form (no LibTorch here: the fuzz target of
/// the JSON reader builds without it).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sadsplat {
namespace gaussians {

/// \brief The training options that choose among named values, as enums: their names (JSON,
/// flags, logs) are choiceNames', read and written only by the option table (train_options.h).
enum class DropMode { kNone, kSemantic, kStructure, kFull };  ///< none|semantic|structure|full
enum class DropRule { kBalanced, kPaper };                    ///< balanced|paper
enum class InitMode { kAuto, kPoints, kRandom };              ///< auto|points|random
enum class TrainDevice { kCpu, kCuda };                       ///< cpu|cuda

/// \brief The names of a choice's values, in the enum's order (the argument picks the enum).
const std::vector<std::string>& choiceNames(DropMode);
const std::vector<std::string>& choiceNames(DropRule);
const std::vector<std::string>& choiceNames(InitMode);
const std::vector<std::string>& choiceNames(TrainDevice);
/// \brief The name of a value ("full", "balanced", "cuda").
template <typename Choice>
const std::string& choiceName(Choice value) {
  return choiceNames(value)[static_cast<std::size_t>(value)];
}
/// \brief The value called `name` (DropMode, DropRule, InitMode or TrainDevice).
/// \throws sadsplat::Error naming `origin` and `key`, with the names, for another name
template <typename Choice>
Choice parseChoice(const std::string& name, const std::string& origin, const std::string& key);

/// \brief The length of the run and the intervals that are not a strategy's own (SH degree, views
/// per step, checkpoints, the random seed).
struct ScheduleOptions {
  int iterations = 7000;  ///< paper: 7000
  int sh_increase_interval = 1000;
  /// Training views rendered per step (and, on semantic steps, as many labelled views); the loss
  /// is their mean. With N data-parallel ranks each rank renders this many, so N ranks with 1
  /// view each train like one process with N views per step.
  int views_per_step = 1;
  int checkpoint_interval = 1000;  ///< 0 = none
  std::uint64_t seed = 42;
};

/// \brief The training loss: the weights of its terms and how they are computed.
struct LossOptions {
  double lambda_ssim = 0.2;  ///< paper: lambda_SSIM = 0.2
  /// The SSIM loss in fused passes on CPU and CUDA (gaussians::ssim); false: the reference
  /// composition of convolutions (gaussians::ssimReference), the same value, slower (for
  /// comparisons).
  bool fused_ssim = true;
  /// On CUDA, the semantic loss in fused kernels (gaussians::semanticLoss); false: the reference
  /// composition of ATen operations (gaussians::semanticLossReference), for comparisons.
  bool fused_semantic_loss = true;
  double lambda_rgb = 1.0;
  double lambda_semantic = 1.0;
  /// Not the paper: weight of a flatness loss, the mean over the Gaussians of their smallest
  /// scale divided by the scene extent (the scale regulariser of PGSR and Gaussian surfels):
  /// Gaussians become discs on the surfaces, so that a facade seen from above is a line, not a
  /// band over the street. 0: off.
  double lambda_flatten = 0.0;
  /// Not the paper: weight of the sparse-depth loss (gaussians/sparse_depth_loss.h), the mean
  /// relative difference between each training view's rendered depth and the depth of the
  /// scene's sparse points it sees (structure-from-motion points; gsplat's `depth_loss`). Ties
  /// the surfaces to what the photos triangulated where the photometric loss alone leaves the
  /// depth free (a capture that sees the ground from one side). 0: off; nothing without points.
  double lambda_sparse_depth = 0.0;
  /// Every this many iterations a labelled view is rendered as well, for the semantic loss
  /// (only 3 of ~63 training views carry labels). 1 = every iteration.
  int semantic_interval = 2;
  /// Supervise the unlabelled training views with the scene's kept pseudo-labels (written by
  /// `sadsplat pseudo-labels`; without them this does nothing). Ground truth always wins.
  bool use_pseudo_labels = true;
  double lambda_pseudo = 1.0;  ///< weight of the semantic loss on pseudo-labelled views
  /// Whether the semantic loss of pseudo-labelled views also trains the decoder (paper: yes).
  /// false: pseudo-labels only move the Gaussians' features and the decoder (the class embedding
  /// space) learns from ground truth alone, so the class mix of the kept pseudo-labels (mostly the
  /// easy classes) cannot shift the decoder's class prior.
  bool pseudo_labels_train_decoder = true;
};

/// \brief The Adam learning rates (3DGS's; the positions' decay with the scene extent).
struct OptimiserOptions {
  double lr_position_init = 1.6e-4;   ///< times the scene extent
  double lr_position_final = 1.6e-6;  ///< times the scene extent
  double lr_sh_dc = 2.5e-3;
  double lr_sh_rest = 2.5e-3 / 20;
  double lr_opacity = 0.05;
  double lr_scaling = 5e-3;
  double lr_rotation = 1e-3;
  double lr_feature = 2.5e-3;
  double lr_decoder = 1e-3;
  double lr_log_alpha = 0.01;
};

/// \brief The densification strategy's options (3DGS's adaptive density control, the split of
/// large Gaussians, the scale limit and the floater removal); gaussians/densification.h reads
/// only these.
struct DensificationOptions {
  int densify_from = 500;
  /// -1: densifyUntilResolved (schedule.h) (2/7 of the iterations).
  int densify_until = -1;
  int densify_interval = 100;
  double densify_grad_threshold = 2e-4;  ///< on the NDC-space gradient, as in 3DGS
  double percent_dense = 0.01;
  double min_opacity = 0.005;
  int opacity_reset_interval = 3000;
  int max_screen_radius = 20;
  int max_gaussians = 3000000;  ///< densification stops growing past this
  /// After the last iteration remove the floaters: Gaussians whose centre fewer than
  /// floater_min_views training views see, or whose largest scale exceeds floater_max_scale x
  /// the scene extent (gaussians/view_coverage.h).
  bool prune_floaters = false;
  /// Not 3DGS: after densify_until, every densify_interval iterations up to iterations -
  /// large_split_last, each Gaussian whose largest scale exceeds large_split_scale x the scene
  /// extent is split in two (3DGS's split: two samples, scales / 1.6), so that no Gaussian stays
  /// huge without removing what it covers. 0 = off.
  double large_split_scale = 0.0;
  int large_split_last = 500;
  /// Not 3DGS: no Gaussian's scale (standard deviation along any axis) exceeds scale_limit x
  /// the scene extent from iteration scale_limit_from on. The log-scales are clamped after every
  /// optimiser step (a projection onto the bound), so the large, blurry Gaussians that the
  /// floater census counts (larger than 0.1 x the extent) do not stay. 0 = off.
  double scale_limit = 0.1;
  /// The iteration from which scale_limit holds. At it, every Gaussian larger than the limit is
  /// first split (3DGS's split, repeated up to 8 times: scales / 1.6 each; the split adds at
  /// most a quarter of the model, the largest first), so that what it covered stays covered; the
  /// clamp then keeps them within the limit. Until then the training
  /// and the drop run as without a limit. -1 (default): iterations - iterations / 7 (6000 of
  /// 7000); 0: from the start, without a split (the large ones are clamped as they form).
  int scale_limit_from = -1;
  int floater_min_views = 2;
  double floater_max_scale = 0.1;
};

/// \brief The semantic-aware drop (paper, "Gaussian Point Drop"); the trainer only carries these,
/// the strategy given to setDropStrategy (semantic_drop::makeDropStrategy) reads them.
struct DropOptions {
  DropMode drop = DropMode::kNone;
  double p_base = 1.0;      ///< paper: P_base = 1.0
  int drop_interval = 500;  ///< paper: every N = 500 iterations
  /// Weight of L_L0. 0.2 was chosen on city seed 1 (0.1 / 0.2 / 0.4) for >= 5x fewer Gaussians
  /// at equal mIoU; it costs ~3 dB PSNR against no drop (0.1: ~1.7 dB, ~4x fewer). See README.
  double lambda_l0 = 0.2;
  /// Not the paper: the L0 weight is 0 before iteration lambda_l0_from and then rises linearly
  /// to lambda_l0 over lambda_l0_ramp iterations (semantic_drop::scheduledL0Weight), so that the
  /// gates learn with the full, densified set before they are pushed shut. 0 / 0 = the paper's
  /// constant weight. Under the balanced rule the same holds for its L0 force, and there is no
  /// drop event before lambda_l0_from either (late pruning).
  int lambda_l0_from = 0;
  int lambda_l0_ramp = 0;
  /// Not the paper: exponent gamma of a per-Gaussian weight on the L0 term, so that the
  /// Gaussians that make least of the training views are pushed shut first. Each P_nonzero in
  /// L_L0 is weighted by (1 + c / median c)^-gamma, normalised to mean 1
  /// (gaussians::inverseContributionWeights), c = the Gaussian's summed blending weight over the
  /// training views (gaussians/contribution.h), recomputed from lambda_l0_from on every
  /// drop_interval iterations. 0 = the paper's plain mean.
  double l0_importance = 0.0;
  double log_alpha_init = 3.0;  ///< gates start open: P(z > 0) = 0.99
  /// Not the paper: the last `recovery_iterations` iterations train without gates, L0 term and
  /// drops. At their start, with a drop, the Gaussians whose deterministic gate is closed go and
  /// every other gate is folded into its opacity (and recovery_prune applies, with or without a
  /// drop); the rest then adapts to the model that remains. 0 = the paper's schedule (gates until
  /// the end).
  int recovery_iterations = 0;
  /// Not the paper: at the start of the recovery, also remove this share of the Gaussians with
  /// the smallest contribution to the training views (sum of their blending weights,
  /// gaussians/contribution.h). 0 = none; in [0, 1).
  double recovery_prune = 0.0;
  /// How the L0 pressure and the drop events are set (docs/GUIDE.md, "The drop rule"):
  /// "balanced" (default, not the paper): the L0 force on each gate of a Gaussian the losses
  /// reached this step is l0_strength x the mean loss force on those gates (no L0 term in the loss,
  /// so image size, Gaussian count, view count and loss level cancel); one drop event removes at
  /// most drop_max_fraction of the Gaussians (those of highest P_drop); when the mean squared error
  /// of four fixed training views (rendered as for evaluation) before a drop event exceeds that
  /// before the previous event by more than drop_guard (and no opacity reset came between), the L0
  /// strength and the cap halve; a Gaussian that no confidence map sees takes the mean confidence
  /// of those seen (0.5 when there are no maps).
  /// "paper": L_L0 = lambda_l0 x mean P_nonzero in the loss, P_drop = P_base (1 - P_conf) P_learned
  /// with P_conf = 0 where no map sees a Gaussian, no cap, no guard.
  DropRule drop_rule = DropRule::kBalanced;
  double l0_strength = 1.0;
  double drop_max_fraction = 0.15;
  double drop_guard = 0.05;
  /// Not the paper (MaskGaussian's masked rasterisation, CVPR 2025): a Gaussian whose sampled gate
  /// is 0 this step still gets a gate gradient — the derivative of the render at gate 0
  /// (RenderSettings::closed_gate_gradients) through a clamp that passes it below 0
  /// (semantic_drop::sampleGate) — so that a closed gate the views need can open again.
  bool closed_gate_gradients = false;
};

/// \brief Every training parameter, with the defaults of the paper / 3DGS, in groups that the
/// trainer's parts receive alone (the densification its DensificationOptions, the drop its
/// DropOptions). Each field is listed once more, in the option table (train_options.h), which
/// gives its key, help and range; the table, JSON and flags see one flat set of keys.
struct TrainConfig : ScheduleOptions,
                     LossOptions,
                     OptimiserOptions,
                     DensificationOptions,
                     DropOptions {
  int feature_dim = 32;  ///< paper: semantic dimension 32
  int max_sh_degree = 3;
  /// On CUDA, each training render's (Gaussian, tile) list is sized from earlier renders' counts
  /// (this margin times the largest) and checked after the backward pass, the step rendered
  /// again when one was short (gaussians/tile_list_capacity.h): the host does not wait for the
  /// GPU once per render. The same values; 0: lists sized by each render's count (waiting).
  double tile_list_margin = 1.25;
  /// Initial Gaussians (gaussians/initialization.h): auto = the scene's sparse points, or
  /// init_random_count random points in the cameras' common view when it has fewer than 4;
  /// points; random.
  InitMode init = InitMode::kAuto;
  int init_random_count = 100000;  ///< 3DGS's random initialisation of synthetic scenes
  std::array<float, 3> background{0, 0, 0};
  TrainDevice device = TrainDevice::kCpu;
  /// Keep the training views in host memory in their 8-bit form and upload each step's views to
  /// the device when it renders them (device memory: the model and a step's views, not every
  /// view as floats); the same values as views held on the device.
  bool stream_views = false;

  /// \brief Checks every option against its range in the option table (train_options.h) and
  /// the rules between options (recovery_iterations below iterations).
  /// \throws sadsplat::Error naming `origin` and the first option that is out of range
  void check(const std::string& origin = "<config>") const;

  /// \brief The configuration as JSON text (every key of the option table).
  std::string toJson() const;
  /// \brief Reads a JSON object; keys not given keep their defaults; unknown keys and values of
  /// the wrong type are errors (ranges are check()'s).
  /// \throws sadsplat::Error naming `origin` and the key
  static TrainConfig fromJson(const std::string& text, const std::string& origin);
};

}  // namespace gaussians
}  // namespace sadsplat
