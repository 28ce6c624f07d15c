// `sadsplat info FILE`: what a cloud, scene directory or scene cache holds.
#include <iostream>
#include <sstream>

#include "commands.h"
#include "sadsplat/gaussians/memory_estimate.h"
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
      std::cout << io::describeSceneCache(path_, scene) << trainingMemory(scene);
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
