// `sadsplat tiles RUN --out DIR`: the model as a 3D Tiles tileset with levels of detail.
#include <iostream>

#include "commands.h"
#include "sadsplat/pipeline/globe_export.h"

namespace sadsplat {
namespace cli {
namespace {

class TilesCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "tiles",
        "The model as a 3D Tiles 1.1 tileset for the globe (CesiumJS): glTF content with "
        "KHR_gaussian_splatting (SPZ), levels of detail by class-aware merges, classes as "
        "feature IDs, placed by the georeference");
    c->add_option("MODEL", in_,
                  "run directory, or a model file (.ply, .pcd, .spz, ...) with "
                  "classes.json / georeference.json beside it")
        ->required();
    c->add_option("--out", out_, "tileset folder (tileset.json, tiles/*.glb)")->required();
    c->add_option("--max-splats", options_.max_splats,
                  "splat budget of a tile: larger tiles split in four, inner tiles merge to it")
        ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 26))
        ->capture_default_str();
    c->add_flag("!--no-spz", options_.spz,
                "plain float accessors instead of the SPZ-compressed payload (CesiumJS 1.145 "
                "draws only SPZ-compressed splats)");
    c->add_option("--sh-degree", options_.sh_degree, "SH degrees kept (0..3)")
        ->check(CLI::Range(0, 3))
        ->capture_default_str();
    c->add_flag("--color-by-class", options_.color_by_class,
                "draw every splat in its class's colour (classes.json), no view-dependent colour: "
                "the class map in 3D for clients that cannot style splats by feature ID");
    c->add_flag("!--merge-across-classes", options_.class_aware,
                "levels of detail may merge Gaussians of different classes");
    return c;
  }
  int run(const Invocation&) override {
    std::cout << pipeline::exportTiles(in_, out_, options_, &std::cerr);
    return 0;
  }

 private:
  std::string in_, out_;
  pipeline::TilesExportOptions options_;
};

}  // namespace

std::unique_ptr<Command> makeTilesCommand() { return std::make_unique<TilesCommand>(); }

}  // namespace cli
}  // namespace sadsplat
