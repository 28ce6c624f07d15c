// `sadsplat view MODEL`: a VTK window (or a screenshot) of one model, or two side by side.
#include <array>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "../cli_support.h"
#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/pipeline/splat_frames.h"
#include "sadsplat/viz/splat_view.h"

namespace sadsplat {
namespace cli {
namespace {

// "R,G,B" with each in 0..255.
std::array<std::uint8_t, 3> parseColour(const std::string& text, const std::string& option) {
  std::array<std::uint8_t, 3> rgb{};
  std::stringstream in(text);
  std::string part;
  int k = 0;
  for (; k < 4 && std::getline(in, part, ','); ++k) {
    char* end = nullptr;
    const long v = std::strtol(part.c_str(), &end, 10);
    if (k == 3 || part.empty() || *end != '\0' || v < 0 || v > 255) k = 4;
    if (k < 3) rgb[k] = static_cast<std::uint8_t>(v);
  }
  if (k != 3) throw Error("<command line>", option, "R,G,B with each 0 to 255", text);
  return rgb;
}

class ViewCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "view",
        "Look at a model in 3D (VTK): splats by class, colour, confidence, gate or opacity");
    c->add_option("MODEL", model_, "run directory, or a .ply / .pcd cloud")->required();
    c->add_option("--mode", options_.mode,
                  "splat: the image sadsplat's rasterizer renders for the camera (classes decoded "
                  "per pixel for a run); points: every Gaussian as a disc")
        ->capture_default_str();
    c->add_option("--device", device_, "where splat mode renders: cpu or cuda")
        ->capture_default_str();
    c->add_option("--color", color_, "class, rgb, confidence, gate or opacity")
        ->capture_default_str();
    c->add_option("--class", classes_, "show only these classes (names or ids, comma-separated)");
    c->add_option("--view", options_.view,
                  "start at this camera of the run's scene (e.g. view_042)");
    c->add_option("--compare", compare_, "a second model beside it, cameras linked");
    c->add_option("--screenshot", options_.screenshot, "write this PNG (offscreen) and exit");
    c->add_option("--size", size_, "window / screenshot size")->capture_default_str();
    c->add_option("--splat-scale", options_.splat_scale,
                  "points mode: factor on every disc's radius")
        ->capture_default_str();
    c->add_option("--background", background_, "background colour R,G,B (0-255)")
        ->capture_default_str();
    return c;
  }

  int run(const Invocation& invocation) override {
    if (!options_.screenshot.empty()) rerunUnderXvfbIfHeadless(invocation);
    options_.color = viz::parseColorMode(color_);
    parseSize(size_, "--size", &options_.width, &options_.height);
    options_.background = parseColour(background_, "--background");
    std::stringstream names(classes_);
    for (std::string name; std::getline(names, name, ',');) {
      if (!name.empty()) options_.classes.push_back(name);
    }
    std::vector<viz::ViewModel> models = {viz::loadViewModel(model_)};
    if (!compare_.empty()) models.push_back(viz::loadViewModel(compare_));
    if (options_.mode == "splat") {
      const std::vector<std::string> paths = {model_, compare_};
      for (std::size_t i = 0; i < models.size(); ++i) {
        auto frames = std::make_shared<pipeline::SplatFrames>(paths[i], device_);
        models[i].frames = [frames](const io::FrameRequest& r) { return frames->render(r); };
      }
    }
    viz::showModels(models, options_, &std::cout);
    return 0;
  }

 private:
  std::string model_, compare_, color_ = "class", classes_, size_ = "1280x720", device_ = "cpu",
                                background_ = "28,30,36";
  viz::SplatViewOptions options_;
};

}  // namespace

std::unique_ptr<Command> makeViewCommand() { return std::make_unique<ViewCommand>(); }

}  // namespace cli
}  // namespace sadsplat
