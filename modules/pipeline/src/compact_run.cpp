// A run with fewer Gaussians (see compact_run.h).
#include "sadsplat/pipeline/compact_run.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/gaussian_merge.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/train_run.h"

namespace sadsplat {
namespace pipeline {
namespace {

// A Hard Concrete log_alpha whose deterministic gate is 1 (sigmoid(10) (1.1 + 0.1) - 0.1 > 1).
constexpr float kOpenGate = 10.0f;

}  // namespace

std::string compactRun(const std::string& run_dir, const std::string& out_dir,
                       const CompactOptions& o) {
  const int ways = (o.count > 0) + (o.ratio > 0) + !o.model.empty();
  if (ways != 1) {
    throw Error(out_dir, "--count / --ratio / --model", "exactly one of them",
                std::to_string(ways) + " given");
  }
  if (o.ratio > 0 && !(o.ratio <= 1)) {
    throw Error(out_dir, "--ratio", "a share of the Gaussians kept, in (0, 1]",
                std::to_string(o.ratio));
  }
  std::error_code same_error;
  if (std::filesystem::equivalent(out_dir, run_dir, same_error)) {
    throw Error(out_dir, "--out", "another directory than the run", "the run itself");
  }
  // Refining trains: the trainer then reads its training views.
  OpenedRun run = openRun(run_dir, "", 0.5, ScenePixels::kLeftOnDisk,
                          o.refine > 0 ? gaussians::TrainerViews::kLoaded
                                       : gaussians::TrainerViews::kCamerasOnly);
  pcl::PointCloud<GaussianPoint> model = labelledCloud(*run.trainer, run.scene);
  const at::Tensor opacity = run.trainer->effectiveOpacity().to(at::kFloat).contiguous();
  const float* a = opacity.data_ptr<float>();
  for (std::size_t i = 0; i < model.size(); ++i) {
    const float alpha = std::clamp(a[i], 1e-6f, 1.0f - 1e-6f);
    model[i].opacity = std::log(alpha / (1.0f - alpha));
    model[i].log_alpha = kOpenGate;
  }
  std::ostringstream summary;
  pcl::PointCloud<GaussianPoint> smaller;
  if (!o.model.empty()) {
    smaller = io::readGaussians(o.model);
    for (GaussianPoint& p : smaller) p.log_alpha = kOpenGate;
    summary << o.model << ": " << smaller.size() << " Gaussians (of the run's " << model.size()
            << ")";
  } else {
    const std::size_t target =
        o.count > 0 ? o.count
                    : std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(
                                                   o.ratio * static_cast<double>(model.size()))));
    filters::CompactResult r = filters::compactGaussians(model, target, o.class_aware);
    smaller = std::move(r.cloud);
    summary << model.size() << " -> " << smaller.size() << " Gaussians (target " << target
            << ", groups' 90th-percentile extent " << r.group_extent << " scene units"
            << (o.class_aware ? ", class-aware" : "") << ")";
  }
  if (o.refine < 0) throw Error(out_dir, "--refine", "iterations >= 0", std::to_string(o.refine));
  run.trainer->setGaussians(smaller);
  for (int i = 0; i < o.refine; ++i) run.trainer->step(/*read_losses=*/false);
  if (o.refine > 0) {
    summary << ", refined " << o.refine << " iterations (" << run.trainer->numGaussians()
            << " Gaussians after)";
  }
  io::makeDirectory(out_dir);
  const io::RunDirectory out(out_dir);
  io::writeTextFileAtomically(out.config(), run.config.toJson());
  io::RunRecord record = io::RunDirectory(run_dir).readRecord();
  writeTrainedRun(out, *run.trainer, run.scene, record);
  summary << "; run " << out_dir << " (`sadsplat eval " << out_dir << "` scores it)\n";
  return summary.str();
}

}  // namespace pipeline
}  // namespace sadsplat
