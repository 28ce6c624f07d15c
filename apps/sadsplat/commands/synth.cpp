// `sadsplat synth`: a procedural aerial benchmark scene (directory, scene cache, survey photos).
#include <iostream>

#include "../cli_support.h"
#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/pipeline/world_truth.h"
#include "sadsplat/synth/aerial_benchmark.h"
#if SADSPLAT_HAVE_OPENCV
#include "sadsplat/synth/scene_writer.h"
#include "sadsplat/synth/survey_photos.h"
#endif

namespace sadsplat {
namespace cli {
namespace {

class SynthCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("synth", "Generate a procedural aerial benchmark scene");
    c->add_option("--kind", kind_, "city, country or port")->capture_default_str();
    c->add_option("--seed", seed_, "scene seed")->capture_default_str();
    c->add_option("--preset", preset_,
                  "demo (320x180), full (1600x900), city-xl (a city of 4x the area, 280 views "
                  "of 1600x900) or city-xxl (16x the area, 1,120 views of 1600x900)");
    c->add_option("--views", views_, "number of views (70)");
    c->add_option("--capture", capture_,
                  "orbit (oblique views around the scene, the paper's), grid (a nadir "
                  "drone-mapping mission, 75 % forward overlap) or grid-oblique (half the views "
                  "on that grid, half on four passes pitched 45 degrees to N, E, S, W)")
        ->check(CLI::IsMember({"orbit", "grid", "grid-oblique"}))
        ->capture_default_str();
    c->add_option("--width", width_, "image width (1600)");
    c->add_option("--height", height_, "image height (900)");
    c->add_option("--points", points_, "sparse points to keep");
    c->add_option("--labelled", labelled_,
                  "labelled views: indices (0,7,28) or \"auto\": as many views as the preset "
                  "labels, chosen as `pick-views` advises a user (those that see most of the "
                  "ground)");
    c->add_option("--out", out_, "scene directory to write (PNG, needs OpenCV)");
    c->add_option("--cache", cache_, "scene cache file to write");
    c->add_flag("--preview", preview_, "also write OUT/preview.png");
    c->add_option("--photos", photos_,
                  "also write the views as survey photos: JPEGs with EXIF GPS and focal length "
                  "(for `sadsplat sfm`)");
    c->add_option("--gps-noise", gps_noise_,
                  "with --photos: horizontal GPS noise (m, 1 sigma per axis), altitude offset, "
                  "altitude wander amplitude, altitude noise (m); e.g. 2,30,25,3 for a camera's "
                  "own receiver")
        ->delimiter(',')
        ->expected(1, 4);
    c->add_option("--gcps", gcps_,
                  "with --photos: about this many ground control points in gcp_list.txt");
    c->add_flag("--colmap-binary", colmap_binary_,
                "with --out: write sparse/0 as a binary COLMAP model (cameras.bin, ...)");
    return c;
  }

  int run(const Invocation&) override {
    if (out_.empty() && cache_.empty() && photos_.empty()) {
      throw Error("<command line>", "synth", "--out DIR, --cache FILE and/or --photos DIR", "none");
    }
    const synth::SynthOptions o = options();
    std::cout << "generating " << kind_ << " seed " << seed_ << ": " << o.views << " views of "
              << o.width << "x" << o.height << " (" << capture_ << ")";
    if (o.capture != synth::Capture::kOrbit) {
      const synth::GridLayout g = synth::gridLayout(o);
      if (o.capture == synth::Capture::kGridOblique) {
        std::cout << ": " << synth::nadirViews(o) << " nadir + " << o.views - synth::nadirViews(o)
                  << " oblique (" << synth::kObliquePitchDeg << " deg, 4 passes)";
      }
      std::cout << ": " << g.lines << " lines of " << g.per_line << " photos at " << g.altitude
                << " m, overlap " << 100 * g.forward_overlap << " % forward, "
                << 100 * g.side_overlap << " % side";
    }
    std::cout << " ..." << std::flush;
    const synth::SynthScene scene = synth::generate(o);
    std::cout << " " << scene.seconds << " s, " << scene.points.size() << " sparse points\n";
    if (!cache_.empty()) io::writeSceneCache(cache_, synth::toScene(scene));
    if (!out_.empty()) {
#if SADSPLAT_HAVE_OPENCV
      synth::writeScene(scene, out_,
                        colmap_binary_ ? synth::ColmapFormat::kBinary : synth::ColmapFormat::kText);
      if (preview_) synth::writeContactSheet(scene, out_ + "/preview.png");
      // The world's truth for other tools (GDAL writes it: not in a build without GDAL).
      if (geo::haveGdal()) std::cout << pipeline::writeWorldTruth(scene.world, out_);
#else
      throw Error(out_, "--out", "a sadsplat build with OpenCV to write PNG scene directories",
                  "a build without it (use --cache)");
#endif
    }
    if (!photos_.empty()) {
#if SADSPLAT_HAVE_OPENCV
      synth::SurveyPhotoOptions p;
      const double* n = gps_noise_.data();
      if (gps_noise_.size() > 0) p.horizontal_noise = n[0];
      if (gps_noise_.size() > 1) p.altitude_offset = n[1];
      if (gps_noise_.size() > 2) p.altitude_wander = n[2];
      if (gps_noise_.size() > 3) p.altitude_noise = n[3];
      p.ground_control_points = gcps_;
      const int written = synth::writeSurveyPhotos(scene, p, photos_);
      std::cout << "photos: " << scene.views.size() << " JPEGs with GPS in " << photos_;
      if (gcps_ > 0) std::cout << ", " << written << " ground control points in gcp_list.txt";
      std::cout << "\n";
#else
      throw Error(photos_, "--photos", "a sadsplat build with OpenCV to write JPEG photos",
                  "a build without it");
#endif
    }
    const synth::SynthStats stats = synth::computeStats(scene);
    std::cout << "effective pixels: " << 100.0 * stats.effective_share << " %\nclass shares:";
    for (std::size_t c = 0; c < scene.classes.size(); ++c) {
      std::cout << " " << scene.classes[c].name << " " << 100.0 * stats.class_share[c] << "%";
    }
    std::cout << "\nwrote";
    for (const std::string* path : {&out_, &cache_, &photos_}) {
      if (!path->empty()) std::cout << " " << *path;
    }
    std::cout << "\n";
    return 0;
  }

 private:
  synth::SynthOptions options() const {
    const synth::SceneKind kind = synth::parseSceneKind(kind_);
    synth::SynthOptions o;
    if (preset_ == "demo") {
      o = synth::SynthOptions::demo(kind, seed_);
    } else if (preset_.empty() || preset_ == "full") {
      o.kind = kind;
      o.seed = seed_;
    } else if (preset_ == "city-xl" || preset_ == "city-xxl") {
      if (kind != synth::SceneKind::kCity) {
        throw Error("<command line>", "--preset " + preset_, "--kind city", kind_);
      }
      o = synth::SynthOptions::tiledCity(seed_, preset_ == "city-xl" ? 2 : 4);
    } else {
      throw Error("<command line>", "--preset", "demo, full, city-xl or city-xxl", preset_);
    }
    if (views_ > 0) o.views = views_;
    o.capture = synth::captureFromName(capture_);
    if (width_ > 0) o.width = width_;
    if (height_ > 0) o.height = height_;
    if (points_ > 0) o.max_points = points_;
    if (labelled_ == "auto") {
      o.labelled_auto = true;
    } else if (!labelled_.empty()) {
      o.labelled = parseIndexList(labelled_, "--labelled");
    }
    return o;
  }

  std::string kind_ = "city", preset_, out_, cache_, capture_ = "orbit", photos_;
  std::vector<double> gps_noise_;
  int gcps_ = 0;
  std::uint64_t seed_ = 0;
  int views_ = -1, width_ = -1, height_ = -1, points_ = -1;
  std::string labelled_;
  bool preview_ = false, colmap_binary_ = false;
};

}  // namespace

std::unique_ptr<Command> makeSynthCommand() { return std::make_unique<SynthCommand>(); }

}  // namespace cli
}  // namespace sadsplat
