// `sadsplat synth`: a procedural aerial benchmark scene (directory and/or scene cache).
#include <iostream>

#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/synth/aerial_benchmark.h"
#if SADSPLAT_HAVE_OPENCV
#include "sadsplat/synth/scene_writer.h"
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
                  "demo (320x180), full (1600x900) or city-xl (a city of 4x the area, 280 views "
                  "of 1600x900)");
    c->add_option("--views", views_, "number of views (70)");
    c->add_option("--width", width_, "image width (1600)");
    c->add_option("--height", height_, "image height (900)");
    c->add_option("--points", points_, "sparse points to keep");
    c->add_option("--labelled", labelled_, "labelled views (0,7,28)")->delimiter(',');
    c->add_option("--out", out_, "scene directory to write (PNG, needs OpenCV)");
    c->add_option("--cache", cache_, "scene cache file to write");
    c->add_flag("--preview", preview_, "also write OUT/preview.png");
    c->add_flag("--colmap-binary", colmap_binary_,
                "with --out: write sparse/0 as a binary COLMAP model (cameras.bin, ...)");
    return c;
  }

  int run(const Invocation&) override {
    if (out_.empty() && cache_.empty()) {
      throw Error("<command line>", "synth", "--out DIR and/or --cache FILE", "neither");
    }
    const synth::SynthOptions o = options();
    std::cout << "generating " << kind_ << " seed " << seed_ << ": " << o.views << " views of "
              << o.width << "x" << o.height << " ..." << std::flush;
    const synth::SynthScene scene = synth::generate(o);
    std::cout << " " << scene.seconds << " s, " << scene.points.size() << " sparse points\n";
    if (!cache_.empty()) io::writeSceneCache(cache_, synth::toScene(scene));
    if (!out_.empty()) {
#if SADSPLAT_HAVE_OPENCV
      synth::writeScene(scene, out_,
                        colmap_binary_ ? synth::ColmapFormat::kBinary : synth::ColmapFormat::kText);
      if (preview_) synth::writeContactSheet(scene, out_ + "/preview.png");
#else
      throw Error(out_, "--out", "a sadsplat build with OpenCV to write PNG scene directories",
                  "a build without it (use --cache)");
#endif
    }
    const synth::SynthStats stats = synth::computeStats(scene);
    std::cout << "effective pixels: " << 100.0 * stats.effective_share << " %\nclass shares:";
    for (std::size_t c = 0; c < scene.classes.size(); ++c) {
      std::cout << " " << scene.classes[c].name << " " << 100.0 * stats.class_share[c] << "%";
    }
    std::cout << "\nwrote " << (out_.empty() ? cache_ : out_) << "\n";
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
    } else if (preset_ == "city-xl") {
      if (kind != synth::SceneKind::kCity) {
        throw Error("<command line>", "--preset city-xl", "--kind city", kind_);
      }
      o = synth::SynthOptions::cityXl(seed_);
    } else {
      throw Error("<command line>", "--preset", "demo, full or city-xl", preset_);
    }
    if (views_ > 0) o.views = views_;
    if (width_ > 0) o.width = width_;
    if (height_ > 0) o.height = height_;
    if (points_ > 0) o.max_points = points_;
    if (!labelled_.empty()) o.labelled = labelled_;
    return o;
  }

  std::string kind_ = "city", preset_, out_, cache_;
  std::uint64_t seed_ = 0;
  int views_ = -1, width_ = -1, height_ = -1, points_ = -1;
  std::vector<int> labelled_;
  bool preview_ = false, colmap_binary_ = false;
};

}  // namespace

std::unique_ptr<Command> makeSynthCommand() { return std::make_unique<SynthCommand>(); }

}  // namespace cli
}  // namespace sadsplat
