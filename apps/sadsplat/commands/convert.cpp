// `sadsplat convert IN OUT`: a cloud into another format (the extensions choose).
#include <iostream>

#include "commands.h"
#include "sadsplat/geo/las_export.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gltf_splats.h"
#include "sadsplat/pipeline/globe_export.h"
#include "sadsplat/pipeline/las_frame.h"

namespace sadsplat {
namespace cli {
namespace {

class ConvertCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "convert",
        "Convert a cloud: Gaussians .ply/.pcd/.splat/.spz/.sog/.glb (also read: .compressed.ply), "
        "semantic clouds .ply/.pcd");
    c->add_option("IN", in_, "input .ply, .pcd, .splat, .spz, .sog or .compressed.ply")->required();
    c->add_option("OUT", out_,
                  "output .ply, .pcd, .splat, .spz, .sog (PlayCanvas), .las (LAS 1.4: centres, "
                  "colour, ASPRS class, in the georeference's UTM zone, else in the maps' local "
                  "metres, z up) or .glb (glTF KHR_gaussian_splatting, "
                  "SPZ-compressed, classes as feature IDs, upright in glTF's y-up axes); "
                  "classes.json and georeference.json are read from the input's folder")
        ->required();
    c->add_option("--classification-map", classification_map_,
                  ".las: JSON {\"class name\": ASPRS code} replacing the default codes");
    c->add_option("--spz-version", options_.spz_version,
                  ".spz: 3 (gzip, every SPZ reader), 4 (zstd, the current version) or 2 (what "
                  "older web viewers read)")
        ->check(CLI::IsMember({2, 3, 4}))
        ->capture_default_str();
    c->add_flag("!--glb-no-spz", glb_.spz, ".glb: plain float accessors instead of SPZ");
    return c;
  }
  int run(const Invocation&) override {
    if (io::lowerExtension(out_) == ".glb") {
      std::cerr << "sadsplat: note: " << pipeline::exportGlb(in_, out_, glb_) << "\n";
      return 0;
    }
    if (io::lowerExtension(out_) == ".las") {
      const geo::LasExportOptions options =
          pipeline::lasOptionsForModel(in_, classification_map_, &std::cerr);
      std::cout << (io::cloudKind(in_) == io::CloudKind::kSemantic
                        ? geo::writeSemanticLas(out_, io::readSemanticCloud(in_), options)
                        : geo::writeGaussiansLas(out_, io::readGaussians(in_), options))
                << "\n";
      return 0;
    }
    const std::string note = io::convertCloudFile(in_, out_, options_);
    if (!note.empty()) std::cerr << "sadsplat: note: " << note << "\n";
    return 0;
  }

 private:
  std::string in_, out_, classification_map_;
  io::ConvertOptions options_;
  io::GltfSplatOptions glb_;
};

}  // namespace

std::unique_ptr<Command> makeConvertCommand() { return std::make_unique<ConvertCommand>(); }

}  // namespace cli
}  // namespace sadsplat
