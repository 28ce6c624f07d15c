#include "sadsplat/pipeline/labelled_cloud.h"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/ortho_render.h"

namespace sadsplat {
namespace pipeline {
namespace {

// Says what a long pass does before it starts, and its time when it ends (nothing without a
// stream).
class Stopwatch {
 public:
  Stopwatch(std::ostream* out, const std::string& what)
      : out_(out), start_(std::chrono::steady_clock::now()) {
    if (out_) *out_ << what << " ..." << std::flush;
  }
  ~Stopwatch() {
    if (!out_) return;
    const std::chrono::duration<double> s = std::chrono::steady_clock::now() - start_;
    std::ostringstream seconds;  // the caller's stream keeps its own format
    seconds << std::fixed << std::setprecision(1) << s.count();
    *out_ << " " << seconds.str() << " s\n";
  }
  Stopwatch(const Stopwatch&) = delete;
  Stopwatch& operator=(const Stopwatch&) = delete;

 private:
  std::ostream* out_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

pcl::PointCloud<GaussianPoint> labelledCloud(const gaussians::Trainer& trainer,
                                             const io::Scene& scene, std::ostream* progress) {
  pcl::PointCloud<GaussianPoint> cloud = trainer.toCloud();
  if (trainer.numClasses() == 0) return cloud;
  const std::vector<gaussians::RasterCamera> cameras = trainingCameras(scene);
  if (cameras.empty()) return cloud;
  const Stopwatch watch(progress, "classes of " + std::to_string(cloud.size()) +
                                      " Gaussians from " + std::to_string(cameras.size()) +
                                      " training views");
  const at::Tensor weights = trainer.renderedClassWeights(cameras).to(at::kFloat).contiguous();
  const at::Tensor seen = (weights.sum(1) > 0).contiguous();
  const at::Tensor best = weights.argmax(1).contiguous();
  const bool* s = seen.data_ptr<bool>();
  const int64_t* b = best.data_ptr<int64_t>();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (s[i]) cloud[i].label = static_cast<std::uint32_t>(b[i]);
  }
  return cloud;
}

std::vector<float> surfaceGaps(const gaussians::Trainer& trainer, const io::Scene& scene,
                               std::ostream* progress) {
  const std::vector<gaussians::RasterCamera> cameras = trainingCameras(scene);
  const Stopwatch watch(progress, "surface check of " + std::to_string(trainer.numGaussians()) +
                                      " Gaussians over " + std::to_string(cameras.size()) +
                                      " training views");
  const at::Tensor gaps =
      trainer.renderedDepthResiduals(cameras, gaussians::SurfaceDepth::kMedianWhereSeen)
          .to(at::kFloat)
          .contiguous();
  return std::vector<float>(gaps.data_ptr<float>(), gaps.data_ptr<float>() + gaps.numel());
}

pcl::PointCloud<GaussianPoint> gaussiansOnSurface(const std::string& run_dir,
                                                  const pcl::PointCloud<GaussianPoint>& model,
                                                  float max_gap, std::ostream* progress) {
  if (!(max_gap > 0) || !std::isfinite(max_gap)) {
    throw Error(run_dir, "--on-surface", "a positive distance in scene units",
                std::to_string(max_gap));
  }
  const OpenedRun run = openRun(run_dir);
  const std::vector<float> gaps = surfaceGaps(*run.trainer, run.scene, progress);
  if (model.size() != gaps.size()) {
    throw Error(run_dir, "model", "the checkpoint's " + std::to_string(gaps.size()) + " Gaussians",
                std::to_string(model.size()));
  }
  pcl::PointCloud<GaussianPoint> kept;
  kept.header = model.header;
  for (std::size_t i = 0; i < model.size(); ++i) {
    if (gaps[i] <= max_gap) kept.push_back(model[i]);
  }
  return kept;
}

}  // namespace pipeline
}  // namespace sadsplat
