// `sadsplat report RUN`: plots and report.md of a training run.
#include <iostream>

#include "../cli_support.h"
#include "commands.h"
#include "sadsplat/viz/training_report.h"

namespace sadsplat {
namespace cli {
namespace {

class ReportCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "report", "Plots and report.md of a training run (loss, Gaussians, drops, IoU per class)");
    c->add_option("RUN", options_.run, "run directory")->required();
    c->add_option("--baseline", options_.baseline, "a run to compare with");
    c->add_option("--out", options_.out, "output directory (default RUN/report)");
    return c;
  }
  int run(const Invocation& invocation) override {
    rerunUnderXvfbIfHeadless(invocation);
    std::cout << "wrote " << viz::writeTrainingReport(options_) << "\n";
    return 0;
  }

 private:
  viz::ReportOptions options_;
};

}  // namespace

std::unique_ptr<Command> makeReportCommand() { return std::make_unique<ReportCommand>(); }

}  // namespace cli
}  // namespace sadsplat
