// `sadsplat import SCENE --out CACHE`: a scene directory into a scene cache.
#include <chrono>
#include <iostream>

#include "commands.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"

namespace sadsplat {
namespace cli {
namespace {

class ImportCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("import", "Import a scene directory into a scene cache");
    c->add_option("SCENE", dir_, "scene directory")->required();
    c->add_option("--out", out_, "scene cache file to write")->required();
    c->add_option("--scale", options_.scale, "image scale in (0, 1]")->capture_default_str();
    c->add_option("--max-width", options_.max_width, "cap on image width (0 = none)");
    return c;
  }
  int run(const Invocation&) override {
    const auto start = std::chrono::steady_clock::now();
    const auto scene = io::importScene(dir_, options_);
    io::writeSceneCache(out_, scene);
    std::cout << "imported " << scene.views.size() << " views, " << scene.points.size()
              << " points into " << out_ << " in "
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
              << " s\n";
    return 0;
  }

 private:
  std::string dir_, out_;
  io::ImportOptions options_;
};

}  // namespace

std::unique_ptr<Command> makeImportCommand() { return std::make_unique<ImportCommand>(); }

}  // namespace cli
}  // namespace sadsplat
