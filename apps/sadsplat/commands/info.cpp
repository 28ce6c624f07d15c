// `sadsplat info FILE`: what a cloud, scene directory or scene cache holds.
#include <iostream>

#include "commands.h"
#include "sadsplat/io/file_info.h"

namespace sadsplat {
namespace cli {
namespace {

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
    std::cout << (cameras_ ? io::describeCameras(path_) : io::describeFile(path_));
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
