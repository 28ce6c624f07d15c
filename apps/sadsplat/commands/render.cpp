// `sadsplat render RUN --out DIR`: what the model sees in every photo (class ids, class colours,
// RGB, depth, confidence), at the photos' own size, or along an orbit of novel views.
#include <iostream>

#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/pipeline/map_products.h"

namespace sadsplat {
namespace cli {
namespace {

class RenderCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "render", "Render a trained run's views: class ids, class colours, RGB, depth, confidence");
    c->add_option("RUN", o_.run, "run directory")->required();
    c->add_option("--out", o_.out, "output directory (one folder per output)")->required();
    c->add_option("--views", o_.views, "all, train, test, or image names separated by commas")
        ->capture_default_str();
    CLI::Option* size =
        c->add_option("--size", size_, "WxH of every image (default: each photo's original size)");
    c->add_option("--scale", o_.scale, "factor of the imported image size instead")->excludes(size);
    c->add_option("--outputs", o_.outputs,
                  "any of class, colour, rgb, depth, confidence (comma-separated)")
        ->delimiter(',')
        ->capture_default_str();
    c->add_option("--path", o_.path, "orbit:N: N novel views on a circle around the scene");
    return c;
  }
  int run(const Invocation&) override {
    if (!size_.empty()) {
      const std::size_t x = size_.find('x');
      char* end = nullptr;
      o_.width =
          x == std::string::npos ? -1 : static_cast<int>(std::strtol(size_.c_str(), &end, 10));
      if (x == std::string::npos || end != size_.c_str() + x) {
        throw Error("<command line>", "--size", "WxH, e.g. 4000x2250", size_);
      }
      o_.height = static_cast<int>(std::strtol(size_.c_str() + x + 1, &end, 10));
      if (*end != '\0' || o_.width <= 0 || o_.height <= 0) {
        throw Error("<command line>", "--size", "WxH, e.g. 4000x2250", size_);
      }
    }
    o_.progress = &std::cout;
    const int n = pipeline::renderRun(o_);
    std::cout << "wrote " << n << " views to " << o_.out << "\n";
    return 0;
  }

 private:
  pipeline::RenderRunOptions o_;
  std::string size_;
};

}  // namespace

std::unique_ptr<Command> makeRenderCommand() { return std::make_unique<RenderCommand>(); }

}  // namespace cli
}  // namespace sadsplat
