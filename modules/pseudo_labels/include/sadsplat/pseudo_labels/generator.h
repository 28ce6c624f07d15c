#pragma once
/// \file generator.h
/// \brief `sadsplat pseudo-labels`: splits every training view into targets, scores each target
/// against every class with a backend, applies the TOP1 / dTOP / entropy filter (the paper's, over
/// all targets of the training set, or per TOP1 class) and the cross-view check, and stores the
/// result in each view's io::ViewPseudoLabels. The paper's filter exactly: PseudoLabelOptions with
/// filter_k = 1, per_class = false, min_view_agreement = 0.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sadsplat/io/scene.h"
#include "sadsplat/pseudo_labels/few_shot_classifier.h"
#include "sadsplat/pseudo_labels/graph_segmentation.h"
#include "sadsplat/pseudo_labels/superpixels.h"
#include "sadsplat/pseudo_labels/target_filter.h"

namespace sadsplat {
namespace pseudo_labels {

/// \brief One partition of a view into targets, with their class scores and features.
struct TargetLayer {
  Segmentation segmentation;
  std::vector<float> scores;  ///< num_regions x C, rows are distributions
  int feature_dim = 0;
  std::vector<float> features;  ///< num_regions x feature_dim
};

/// \brief The targets of one view: one or more layers of the same image size. Targets of
/// different layers overlap (multi-granularity masks, like SAM's whole / part / sub-part); every
/// target of every layer is one sample of the filter. Layer 0 is the finest.
struct ViewTargets {
  std::vector<TargetLayer> layers;
};

/// \brief Resolves overlapping layers into the one partition that io::ViewPseudoLabels stores:
/// the common refinement of the layers. Each refined region takes the kept target with the
/// highest TOP1 among the targets that cover it, or, when none of them is kept, the target of the
/// finest layer that has one there (scores and features copied, not kept). Pixels of no target
/// in any layer (-1) stay -1.
/// \param[in] layers the view's layers (same image size and feature dimension)
/// \param[in] C number of classes (columns of the scores)
/// \param[in] top1 per layer, per target: the TOP1 measure of the filter
/// \param[in] kept per layer, per target: the filter's decision
/// \param[out] refined_kept per refined region: kept
/// \throws sadsplat::Error if there is no layer or the layers differ in size or feature dim
TargetLayer resolveLayers(const std::vector<TargetLayer>& layers, int C,
                          const std::vector<std::vector<double>>& top1,
                          const std::vector<std::vector<std::uint8_t>>& kept,
                          std::vector<std::uint8_t>& refined_kept);

/// \brief Progress lines ("view 12/67 ..."); may be empty.
using ProgressFn = std::function<void(const std::string&)>;

/// \brief A mask generator + region scorer (the two halves of the paper's preprocessing).
class TargetScorer {
 public:
  using Ptr = std::shared_ptr<TargetScorer>;
  virtual ~TargetScorer() = default;
  virtual std::string name() const = 0;
  /// \brief Targets and scores for the views `views` (indices into scene.views).
  virtual std::vector<ViewTargets> score(const io::Scene& scene, const std::vector<int>& views,
                                         const ProgressFn& progress) = 0;
};

/// \brief The built-in backend's mask generator.
enum class MaskGenerator {
  kSlic,   ///< SLIC superpixels: equal-size targets
  kGraph,  ///< graph-based segmentation: large targets in homogeneous areas
  /// SLIC at the region sizes S * scale for each of `multiscale` (overlapping layers; S is
  /// SlicOptions::region_size), one classifier fitted on the labelled regions of every layer
  kSlicMultiscale,
};

/// \brief Superpixel size for a W x H view when BuiltinOptions::scale_region_size is set.
int scaledRegionSize(int region_size, int width, int height);

/// \brief Options of the built-in backend.
struct BuiltinOptions {
  MaskGenerator targets = MaskGenerator::kSlic;
  SlicOptions superpixels;
  /// superpixels.region_size is meant for an 800x450 view and scales with the image: S *
  /// sqrt(W * H / (800 * 450)), rounded, at least 4 px, so a target covers the same share of the
  /// ground at any resolution (at 320x180 16 px superpixels span 2.5x the ground and the scorer
  /// fell from 90.9 % to 79.7 % right before the filter). false: region_size pixels as given.
  bool scale_region_size = true;
  GraphSegmentationOptions graph;
  std::vector<int> multiscale{1, 2, 4};  ///< region-size factors of kSlicMultiscale, ascending
  ClassifierOptions classifier;
  bool geometry = true;     ///< use the sparse points' heights as a descriptor
  double min_purity = 0.7;  ///< a labelled region trains the scorer if this share agrees
};

/// \brief The built-in backend: targets from `options.targets`, few-shot classifier fitted on the
/// labelled views.
/// \throws sadsplat::Error (from score) if no labelled view has labels or the scales are bad
TargetScorer::Ptr makeBuiltinScorer(const BuiltinOptions& options = {});

/// \brief Options of a pseudo-label run.
struct PseudoLabelOptions {
  /// Thresholds mean + k std (the paper: k = 1). Default 0 (not the paper): keep a target whose
  /// TOP1 and dTOP are above their mean and whose entropy is below it. k = 1 keeps ~16 % of the
  /// pixels by construction; k = 0 keeps 48-61 % at about the same precision (98.6-99.3 % vs
  /// 98.8-99.7 % on the nine benchmark scenes) and trained to +0.6 to +5.4 mIoU over k = 1 on
  /// six of them (H100; docs/measurements/h100_filter_k). k < 0 tightens the entropy
  /// threshold while loosening the others (worse on city 2).
  double filter_k = 0.0;
  /// Where TOP1 / dTOP are measured. Both backends score with softmax probabilities; on the
  /// log-odds scale dTOP = log(p1 / p2) is, for CLIP, logit_scale * (cos1 - cos2): the paper's
  /// dTOP on cosine similarities up to a factor, which the mean + k std rule ignores.
  ScoreScale scale = ScoreScale::kLogOdds;
  /// Class-balanced: mean and std over the targets of the same TOP1 class instead of over all
  /// targets (not the paper; the paper's pooled filter is per_class = false). Pooled statistics
  /// keep the easy classes and starve the confusable ones (road, paved, grass: < 1 % of their
  /// pixels), which biased the trained model (README, "Measured"). Default together with the
  /// cross-view check, which removes the wrong labels that balancing lets in.
  bool per_class = true;
  /// Reliability check (not the paper): a class whose kept pseudo-labels are right on fewer than
  /// this share of the labelled views' pixels (scored held out by the built-in backend) loses its
  /// pseudo-labels everywhere; 0 = off. Needs `min_check_pixels` kept pixels of the class there.
  double min_class_precision = 0;
  std::size_t min_check_pixels = 500;
  /// Cross-view check (not the paper): every sparse point seen in a target is also seen by other
  /// training views, each of which votes for the class of its own target there (argmax, kept or
  /// not). A kept target whose class gets less than this share of those votes is unkept; 0 = off
  /// (the paper). Does nothing on a scene without sparse points.
  /// A class confused with another in one view only (water read as road under one sun angle) is
  /// outvoted; a confusion that every view makes is not. Targets with fewer than
  /// `min_view_votes` votes keep the filter's decision.
  double min_view_agreement = 0.5;
  std::size_t min_view_votes = 10;
};

/// \brief What a run did.
struct PseudoLabelSummary {
  std::string backend;
  int views = 0;
  std::size_t targets = 0, kept_targets = 0;  ///< all targets of all layers; passed the filter
  /// Stored regions (the layers' common refinement, = targets with one layer) still kept after
  /// the per-class check: what supervises training.
  std::size_t kept_regions = 0;
  TargetStatistics statistics;                     ///< over all targets
  std::vector<TargetStatistics> class_statistics;  ///< per TOP1 class, when per_class
  /// Per class, on the labelled training views: kept pseudo-label pixels and how many of them
  /// agree with the ground truth (ignore pixels not counted).
  std::vector<std::size_t> check_pixels, check_correct;
  std::vector<bool> class_rejected;  ///< per class: pseudo-labels removed by the reliability check
  /// Per class: stored regions unkept by the cross-view check (empty when it is off).
  std::vector<std::size_t> view_check_removed;
};

/// \brief The cross-view check (PseudoLabelOptions::min_view_agreement) on the pseudo-labels
/// stored in `views` (generatePseudoLabels runs it before the class check).
/// \param[in] views indices into scene.views, each with pseudo-labels
/// \param[in] min_agreement share of the other views' votes a kept region's class needs
/// \param[in] min_votes fewer votes than this leave a region as it is
/// \return per class, the regions it unkept
std::vector<std::size_t> applyViewAgreementCheck(io::Scene& scene, const std::vector<int>& views,
                                                 double min_agreement, std::size_t min_votes);

/// \brief Runs `scorer` on every training view of `scene`, filters, and fills `view.pseudo`
/// of those views (other views' pseudo-labels are cleared).
PseudoLabelSummary generatePseudoLabels(io::Scene& scene, TargetScorer& scorer,
                                        const PseudoLabelOptions& options = {},
                                        const ProgressFn& progress = {});

}  // namespace pseudo_labels
}  // namespace sadsplat
