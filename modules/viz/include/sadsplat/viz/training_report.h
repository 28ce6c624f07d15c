#pragma once
/// \file training_report.h
/// \brief `sadsplat report RUN [--baseline RUN_B]`: plots of a training run (VTK charts, PNG) and
/// a report.md that puts them together with the metrics and the test-view panels.
///
/// Writes into the output directory (default RUN/report/):
/// - loss.png: total, RGB and semantic loss over the iterations (train_log.jsonl), and the
///   rest of the total (L0 and other regularisers); the baseline's total when given;
/// - gaussians.png: Gaussians over the iterations, the drop events marked; the baseline's curve;
/// - per_class_iou.png: IoU per class of the run (and the baseline) from metrics.json;
/// - report.md: the table (mIoU, mAcc, OA, PSNR, SSIM, Gaussians, iterations, training time;
///   the baseline beside), the drop events, the plots, and the panels of `sadsplat eval`.

#include <string>

namespace sadsplat {
namespace viz {

/// \brief What to report on.
struct ReportOptions {
  std::string run;       ///< run directory (train_log.jsonl; metrics.json after `sadsplat eval`)
  std::string baseline;  ///< a second run to compare with, or empty
  std::string out;       ///< output directory; empty: RUN/report
};

/// \brief Writes the report; returns the path of report.md.
/// \throws sadsplat::Error naming the run and file when a log or metrics file is missing or
/// invalid, or there is no display for VTK
std::string writeTrainingReport(const ReportOptions& options);

}  // namespace viz
}  // namespace sadsplat
