// `sadsplat info FILE`: what a cloud, scene directory or scene cache holds.
#include <algorithm>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "sadsplat/gaussians/memory_estimate.h"
#include "sadsplat/geo/annotation_views.h"
#include "sadsplat/io/file_info.h"
#include "sadsplat/io/scene_cache.h"

namespace sadsplat {
namespace cli {
namespace {

// What training the scene with the defaults would hold on a CUDA device, views held and
// streamed (gaussians/memory_estimate.h): whether it fits a card before it is trained.
std::string trainingMemory(const io::Scene& scene) {
  gaussians::TrainConfig config;
  config.device = gaussians::TrainDevice::kCuda;
  std::ostringstream out;
  out << "training memory on a CUDA device (defaults, estimated):\n"
      << "  views held:      " << gaussians::estimateTrainingMemory(scene, config).describe()
      << "\n";
  config.stream_views = true;
  out << "  --stream-views:  " << gaussians::estimateTrainingMemory(scene, config).describe()
      << "\n  (train --max-gpu-memory GiB cuts the scene into as few blocks as fit)\n";
  return out.str();
}

// How much of the ground the annotated views see, and the photo that would add the most
// (geo/annotation_views.h): empty for a scene without annotated views or sparse points.
std::string annotationCoverage(const io::Scene& scene) {
  const bool labelled = std::any_of(scene.views.begin(), scene.views.end(),
                                    [](const io::View& v) { return v.labelled && v.train; });
  if (!labelled || scene.points.empty()) return "";
  geo::AnnotationViewOptions options;
  options.count = 1;
  options.keep_labelled = true;
  const geo::AnnotationViews c = geo::chooseAnnotationViews(scene, options, "<info>");
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << "annotated views see " << 100 * c.kept_share << " % of the ground (sparse points)";
  if (!c.picked.empty()) {
    out << "; the photo that adds the most: " << scene.views[c.picked[0]].name << " (+"
        << 100 * (c.cumulative_share[0] - c.kept_share) << " %, `pick-views --keep-labelled`)";
  }
  return out.str() + "\n";
}

class InfoCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "info", "Summarise a cloud (.ply .pcd .splat .spz .sog), scene directory or scene cache");
    c->add_option("FILE", path_, "file or scene directory")->required();
    c->add_flag("--cameras", cameras_,
                "scene cache or directory: every view's camera as CSV (intrinsics, world-to-camera "
                "pose as COLMAP writes it)");
    return c;
  }
  int run(const Invocation&) override {
    if (cameras_) {
      std::cout << io::describeCameras(path_);
    } else if (io::isSceneCache(path_)) {
      const io::Scene scene = io::readSceneCache(path_);
      std::cout << io::describeSceneCache(path_, scene) << annotationCoverage(scene)
                << trainingMemory(scene);
    } else {
      std::cout << io::describeFile(path_);
    }
    return 0;
  }

 private:
  std::string path_;
  bool cameras_ = false;
};

}  // namespace

std::unique_ptr<Command> makeInfoCommand() { return std::make_unique<InfoCommand>(); }

}  // namespace cli
}  // namespace sadsplat
