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
    return c;
  }
  int run(const Invocation&) override {
    std::cout << io::describeFile(path_);
    return 0;
  }

 private:
  std::string path_;
};

}  // namespace

std::unique_ptr<Command> makeInfoCommand() { return std::make_unique<InfoCommand>(); }

}  // namespace cli
}  // namespace sadsplat
