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
  // Half resolution, as `sadsplat train SCENE` imports (the paper trains at half resolution).
  ImportCommand() { options_.scale = 0.5; }
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("import", "Import a scene directory into a scene cache");
    c->add_option("SCENE", dir_, "scene directory")->required();
    c->add_option("--out", out_, "scene cache file to write")->required();
    c->add_option("--scale", options_.scale, "image scale in (0, 1]")->capture_default_str();
    c->add_option("--max-width", options_.max_width, "cap on image width (0 = none)");
    c->add_option("--annotations", options_.annotations,
                  "LabelMe JSON (a file or a folder of them) or COCO JSON (CVAT, Label Studio): "
                  "polygons / RLE masks rasterised into the views' label maps");
    c->add_option("--test-every", options_.test_every,
                  "without split.json: every Nth view is a test view (0: none)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    return c;
  }
  int run(const Invocation&) override {
    const auto start = std::chrono::steady_clock::now();
    const auto scene = io::importScene(dir_, options_);
    io::writeSceneCache(out_, scene);
    int train = 0, test = 0, labelled = 0, labelled_test = 0;
    for (const auto& v : scene.views) {
      train += v.train;
      test += v.test;
      labelled += v.labelled;
      labelled_test += v.test && !v.labels.empty();
    }
    std::cout << "views: " << train << " training (" << labelled << " with labels), " << test
              << " test (" << labelled_test << " with labels); classes: " << scene.classes.size()
              << (scene.georeference ? "; georeferenced" : "") << "\n";
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
