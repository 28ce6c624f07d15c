// `sadsplat view MODEL`: a VTK window (or a screenshot) of one model, or two side by side.
#include <iostream>
#include <sstream>

#include "../cli_support.h"
#include "commands.h"
#include "sadsplat/viz/splat_view.h"

namespace sadsplat {
namespace cli {
namespace {

class ViewCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "view",
        "Look at a model in 3D (VTK): splats by class, colour, confidence, gate or opacity");
    c->add_option("MODEL", model_, "run directory, or a .ply / .pcd cloud")->required();
    c->add_option("--color", color_, "class, rgb, confidence, gate or opacity")
        ->capture_default_str();
    c->add_option("--class", classes_, "show only these classes (names or ids, comma-separated)");
    c->add_option("--view", options_.view,
                  "start at this camera of the run's scene (e.g. view_042)");
    c->add_option("--compare", compare_, "a second model beside it, cameras linked");
    c->add_option("--screenshot", options_.screenshot, "write this PNG (offscreen) and exit");
    c->add_option("--size", size_, "window / screenshot size")->capture_default_str();
    c->add_option("--splat-scale", options_.splat_scale, "factor on every splat's radius")
        ->capture_default_str();
    return c;
  }

  int run(const Invocation& invocation) override {
    if (!options_.screenshot.empty()) rerunUnderXvfbIfHeadless(invocation);
    options_.color = viz::parseColorMode(color_);
    parseSize(size_, "--size", &options_.width, &options_.height);
    std::stringstream names(classes_);
    for (std::string name; std::getline(names, name, ',');) {
      if (!name.empty()) options_.classes.push_back(name);
    }
    std::vector<viz::ViewModel> models = {viz::loadViewModel(model_)};
    if (!compare_.empty()) models.push_back(viz::loadViewModel(compare_));
    viz::showModels(models, options_, &std::cout);
    return 0;
  }

 private:
  std::string model_, compare_, color_ = "class", classes_, size_ = "1280x720";
  viz::SplatViewOptions options_;
};

}  // namespace

std::unique_ptr<Command> makeViewCommand() { return std::make_unique<ViewCommand>(); }

}  // namespace cli
}  // namespace sadsplat
