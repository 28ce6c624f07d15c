#pragma once
/// \file evaluation.h
/// \brief Evaluating a trained model on the test views of a scene: class maps, confusion
/// matrix, mIoU / mAcc / OA, PSNR / SSIM, metrics.json and per-view PNG panels.

#include <string>
#include <vector>

#include "sadsplat/eval/metrics.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace eval {

/// \brief The model's floaters, counted against the scene's cameras (gaussians/view_coverage.h):
/// what a user sees from new angles and the test views barely score.
struct FloaterCensus {
  double extent = 0;                       ///< scene extent (3DGS: from the camera centres)
  std::int64_t larger_than_2pct = 0;       ///< largest scale (std. dev.) > 0.02 x extent
  std::int64_t larger_than_10pct = 0;      ///< > 0.1 x extent (what 3DGS prunes after resets)
  std::int64_t seen_by_under_2_views = 0;  ///< centre inside fewer than 2 training views
};

/// \brief Counts the floaters of the trainer's model against the scene's cameras.
FloaterCensus countFloaters(const gaussians::Trainer& trainer, const io::Scene& scene);

/// \brief How many training views must see a pixel's surface for EvalResult::psnr_covered.
constexpr int kCoveredMinViews = 2;

/// \brief The scores of one evaluated view.
struct ViewScore {
  std::string name;
  double psnr = 0;
  double ssim = 0;
  /// Share of its labelled pixels (inside the mask) whose predicted class is right; NaN for a
  /// view without a label map or a model without classes.
  double accuracy = 0;
};

/// \brief Everything measured on the test views.
struct EvalResult {
  ConfusionMatrix confusion{1};
  double psnr = 0;  ///< mean over test views
  double ssim = 0;  ///< mean over test views
  /// PSNR over the covered pixels only: those whose surface point at least kCoveredMinViews
  /// training views see. The surface point: the pixel back-projected at the depth of the scene's
  /// sparse points (gaussians::sparseDepthImage: the same pixels for every model), or at the
  /// model's expected depth in a view no sparse point falls into. Mean over the views with a
  /// covered pixel; NaN when none has one. Where a capture leaves the ground of a held-out view
  /// unseen (the ends of a survey strip), `psnr` scores extrapolation; this does not.
  double psnr_covered = 0;
  double covered_fraction = 0;  ///< covered pixels / evaluated pixels (inside the views' masks)
  std::string covered_depth;    ///< "sparse points", or "model" when a view used the model's
  /// Mean time to render one test view as evaluation renders it (RGB, features, depth), in ms:
  /// 3 renders per view after a warm-up, each waited for (on CUDA, includes one small copy).
  double render_ms = 0;
  std::vector<std::string> views;
  std::vector<ViewScore> per_view;  ///< in the order of `views`
  FloaterCensus floaters;
  int labelled_views = 0;  ///< evaluated views with a label map (the confusion matrix's)
  bool held_out = false;   ///< the views are the scene's test views (else its training views)
  std::string miou_note;   ///< why there are no class metrics; empty when there are
};

/// \brief Renders every test view (every view if the scene has no test split) and scores it:
/// PSNR / SSIM on all of them, the confusion matrix on those with a label map (none: the class
/// metrics are null and EvalResult::miou_note says why). If `panel_dir` is not empty and the build
/// has OpenCV, writes one PNG per view there: image | render | ground truth | prediction | error
/// mask (image | render without classes). Views whose pixels wait in a scene cache
/// (io::readSceneCacheWithoutPixels) are read one at a time.
/// \throws sadsplat::Error if the scene has no view, or a view's pixels cannot be read
EvalResult evaluate(const gaussians::Trainer& trainer, const io::Scene& scene,
                    const std::string& panel_dir = "");

/// \brief Run facts written next to the metrics.
struct RunFacts {
  std::int64_t num_gaussians = 0;
  int iterations = 0;
  double train_seconds = 0;
  std::string device;
};

/// \brief metrics.json text: miou, macc, oacc, per_class_iou, psnr, ssim, num_gaussians,
/// floaters, iterations, train_seconds, device, classes, confusion_matrix, views, per_view
/// (name, psnr, ssim, accuracy or null).
std::string metricsJson(const EvalResult& result, const std::vector<ClassInfo>& classes,
                        const RunFacts& facts);

}  // namespace eval
}  // namespace sadsplat
