// `sadsplat convert IN OUT`: a cloud into another format (the extensions choose).
#include <iostream>

#include "commands.h"
#include "sadsplat/io/cloud_files.h"

namespace sadsplat {
namespace cli {
namespace {

class ConvertCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "convert",
        "Convert a cloud: Gaussians .ply/.pcd/.splat/.spz (also read: .sog, .compressed.ply), "
        "semantic clouds .ply/.pcd");
    c->add_option("IN", in_, "input .ply, .pcd, .splat, .spz, .sog or .compressed.ply")
        ->required();
    c->add_option("OUT", out_, "output .ply, .pcd, .splat or .spz")->required();
    c->add_option("--spz-version", options_.spz_version,
                  ".spz: 3 (gzip, every SPZ reader), 4 (zstd, the current version) or 2 (what "
                  "older web viewers read)")
        ->check(CLI::IsMember({2, 3, 4}))
        ->capture_default_str();
    return c;
  }
  int run(const Invocation&) override {
    const std::string note = io::convertCloudFile(in_, out_, options_);
    if (!note.empty()) std::cerr << "sadsplat: note: " << note << "\n";
    return 0;
  }

 private:
  std::string in_, out_;
  io::ConvertOptions options_;
};

}  // namespace

std::unique_ptr<Command> makeConvertCommand() { return std::make_unique<ConvertCommand>(); }

}  // namespace cli
}  // namespace sadsplat
