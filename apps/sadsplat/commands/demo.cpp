// `sadsplat demo`: the small benchmark city end to end on the CPU.
#include <iostream>

#include "commands.h"
#include "sadsplat/pipeline/demo.h"

namespace sadsplat {
namespace cli {
namespace {

class DemoCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("demo",
                                     "Generate the demo city, pseudo-label it, train on CPU with "
                                     "the semantic-aware drop, evaluate");
    c->add_option("--out", out_, "output directory")->capture_default_str();
    c->add_option("--iterations", iterations_, "training iterations")->capture_default_str();
    c->add_flag("--baseline", baseline_, "no pseudo-labels and no drop (the paper's Net-1)");
    return c;
  }
  int run(const Invocation&) override {
    return pipeline::runDemo(out_, iterations_, std::cout, baseline_);
  }

 private:
  std::string out_ = "out/demo";
  int iterations_ = 600;
  bool baseline_ = false;
};

}  // namespace

std::unique_ptr<Command> makeDemoCommand() { return std::make_unique<DemoCommand>(); }

}  // namespace cli
}  // namespace sadsplat
