// `sadsplat compact RUN --count N | --ratio R --out RUN2`: a run with fewer Gaussians.
#include <iostream>

#include "commands.h"
#include "sadsplat/pipeline/compact_run.h"

namespace sadsplat {
namespace cli {
namespace {

class CompactCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "compact",
        "A run with fewer Gaussians: neighbours merged by moment matching, class by class (the "
        "levels of detail of `tiles`), written as a run directory that eval/render/ortho/tiles "
        "take");
    c->add_option("RUN", run_, "run directory")->required();
    c->add_option("--out", out_, "the compacted run directory")->required();
    c->add_option("--count", options_.count, "at most this many Gaussians");
    c->add_option("--ratio", options_.ratio, "or this share of the model's Gaussians, in (0, 1]");
    c->add_option("--model", options_.model,
                  "or these Gaussians (a model file in the run's frame, e.g. another tool's "
                  "simplification of the run's model), scored with the run's decoder");
    c->add_option("--refine", options_.refine,
                  "then train the smaller model this many iterations more on the run's scene "
                  "(final learning rates, no densification or drop)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    c->add_flag("!--merge-across-classes", options_.class_aware,
                "merges may join Gaussians of different classes");
    return c;
  }
  int run(const Invocation&) override {
    std::cout << pipeline::compactRun(run_, out_, options_);
    return 0;
  }

 private:
  std::string run_, out_;
  pipeline::CompactOptions options_;
};

}  // namespace

std::unique_ptr<Command> makeCompactCommand() { return std::make_unique<CompactCommand>(); }

}  // namespace cli
}  // namespace sadsplat
