// `sadsplat sfm PHOTOS --out SCENE`: a folder of photos into a scene directory (COLMAP's
// reconstruction, undistorted images, the georeference from the photos' GPS).
#include <iostream>

#include "commands.h"
#include "sadsplat/pipeline/sfm_run.h"

namespace sadsplat {
namespace cli {
namespace {

class SfmCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "sfm", "Reconstruct the cameras of a folder of photos with COLMAP into a scene directory");
    c->add_option("PHOTOS", o_.photos, "folder of photos (JPEG, PNG, TIFF)")->required();
    c->add_option("--out", o_.out, "scene directory to write")->required();
    c->add_option("--matcher", o_.matcher,
                  "auto: exhaustive up to 40 photos, spatial when most carry GPS, else "
                  "sequential")
        ->check(CLI::IsMember({"auto", "exhaustive", "sequential", "spatial"}))
        ->capture_default_str();
    c->add_option("--max-image-size", o_.max_image_size,
                  "longest image side for features and for the scene's images")
        ->check(CLI::Range(100, 100000))
        ->capture_default_str();
    c->add_flag("!--camera-per-photo", o_.single_camera,
                "calibrate each photo's camera alone (default: one camera for all)");
    c->add_option("--threads", o_.threads, "COLMAP's threads (-1: every core)")
        ->capture_default_str();
    c->add_option("--gps-inlier", o_.gps_inlier_metres,
                  "metres between a photo's GPS and its fitted camera centre for an inlier")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    c->add_option("--colmap", o_.colmap, "the COLMAP program")->capture_default_str();
    return c;
  }
  int run(const Invocation&) override {
    o_.progress = &std::cout;
    pipeline::sfmRun(o_);
    std::cout << "next: sadsplat train " << o_.out << " --out RUN\n";
    return 0;
  }

 private:
  pipeline::SfmOptions o_;
};

}  // namespace

std::unique_ptr<Command> makeSfmCommand() { return std::make_unique<SfmCommand>(); }

}  // namespace cli
}  // namespace sadsplat
