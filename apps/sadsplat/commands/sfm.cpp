// `sadsplat sfm PHOTOS --out SCENE`: a folder of photos into a scene directory (COLMAP's
// reconstruction, undistorted images, the georeference from the photos' GPS or from ground
// control points).
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
    c->add_option("--gps-accuracy", o_.gps_accuracy,
                  "horizontal GPS accuracy, metres (1 sigma) the georeference starts from; 0: "
                  "what the photos state (EXIF), else 5 m. Inliers then come from the measured "
                  "noise")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    c->add_option("--gcp", o_.gcp,
                  "ground control points, OpenDroneMap's gcp_list.txt (default: PHOTOS/"
                  "gcp_list.txt when it exists); points named CHK*/check* are check points")
        ->check(CLI::ExistingFile);
    c->add_option("--match-neighbors", o_.match_neighbors,
                  "spatial matcher: match each photo with its k nearest by GPS")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    c->add_option("--match-distance", o_.match_distance,
                  "spatial matcher: only photos within this many metres (0: any)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    c->add_flag("!--keep-focal", o_.refine_focal,
                "keep the focal length of the photos' EXIF (the mapper does not refine it)");
    c->add_option("--colmap", o_.colmap, "the COLMAP program")->capture_default_str();
    return c;
  }
  int run(const Invocation&) override {
    o_.progress = &std::cout;
    pipeline::sfmRun(o_);
    std::cout << "next: sadsplat train " << o_.out << " --out RUN (RGB only), or for classes: "
              << "sadsplat pick-views " << o_.out << " (the photos to annotate), then "
              << "sadsplat import " << o_.out << " --annotations FILE_OR_FOLDER --out S.cache\n";
    return 0;
  }

 private:
  pipeline::SfmOptions o_;
};

}  // namespace

std::unique_ptr<Command> makeSfmCommand() { return std::make_unique<SfmCommand>(); }

}  // namespace cli
}  // namespace sadsplat
