#pragma once
/// \file experiment_table.h
/// \brief The benchmark tables of many trainings: reads the evaluated runs of an experiment
/// folder, RESULTS/<kind>_<scene seed>/<configuration>_t<training seed>/metrics.json (as
/// scripts/gpu/table_runs.sh writes them), and writes Markdown tables of mean ± standard
/// deviation per scene and per scene kind, with the Gaussian count relative to a baseline
/// configuration and the per-class IoU.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace sadsplat {
namespace eval {

/// \brief One evaluated training.
struct ExperimentRun {
  std::string scene;   ///< e.g. "city_0"
  std::string kind;    ///< the scene name before its last '_': "city"
  std::string config;  ///< e.g. "full"
  int training_seed = 0;
  double miou = 0, psnr = 0, ssim = 0;  ///< mIoU as a fraction, PSNR in dB
  double gaussians = 0;
  double large_floaters = 0;  ///< Gaussians larger than 10 % of the scene extent (-1: not counted)
  std::map<std::string, double> class_iou;  ///< classes present in the test views
};

/// \brief Every RESULTS/<scene>/<config>_t<seed>/metrics.json, sorted by scene, configuration
/// and seed. Folders without metrics.json (runs that did not finish) are skipped.
/// \throws sadsplat::Error naming the file when a metrics.json or a folder name is malformed
std::vector<ExperimentRun> readExperimentRuns(const std::string& results_dir);

/// \brief Mean and sample standard deviation (0 for one value).
struct MeanStd {
  double mean = 0, std = 0;
  int n = 0;
};
MeanStd meanStd(const std::vector<double>& values);

/// \brief Markdown: per scene, then per scene kind, one row per configuration (the baseline
/// first): runs, mIoU %, PSNR dB, SSIM, Gaussians, "fewer" (baseline Gaussians / these, means)
/// and the large floaters, each mean ± std; then per kind the per-class IoU of each
/// configuration. `baseline` names the configuration the counts are compared with (skipped when
/// absent).
std::string experimentTables(const std::vector<ExperimentRun>& runs, const std::string& baseline);

/// \brief One point of the compactness-quality frontier: a configuration on one scene against the
/// baseline configuration on the same scene, each the mean over its training seeds.
struct FrontierPoint {
  std::string scene;
  std::string config;
  int runs = 0;              ///< trainings of this configuration on this scene
  double fewer = 0;          ///< baseline Gaussians / these (means)
  double miou_change = 0;    ///< mIoU minus the baseline's, in points (%)
  double psnr_change = 0;    ///< PSNR minus the baseline's, in dB
};

/// \brief The frontier points of every configuration (the baseline included, at 1x / 0 / 0) on
/// every scene that has baseline runs, sorted by scene and configuration.
std::vector<FrontierPoint> frontierPoints(const std::vector<ExperimentRun>& runs,
                                          const std::string& baseline);

}  // namespace eval
}  // namespace sadsplat
