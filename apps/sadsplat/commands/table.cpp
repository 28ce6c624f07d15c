// `sadsplat table RESULTS`: the tables (and frontier charts) of an experiment folder.
#include <iostream>

#include "../cli_support.h"
#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/eval/experiment_table.h"
#include "sadsplat/io/atomic_file.h"
#if SADSPLAT_HAVE_VIZ
#include "sadsplat/viz/experiment_charts.h"
#endif

namespace sadsplat {
namespace cli {
namespace {

class TableCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "table",
        "Tables of an experiment folder: RESULTS/<kind>_<seed>/<config>_t<seed>/metrics.json");
    c->add_option("RESULTS", results_, "experiment results folder")->required();
    c->add_option("--baseline", baseline_, "configuration to compare the counts with")
        ->capture_default_str();
    c->add_option("--out", out_, "also write the Markdown to this file");
    c->add_option("--plots", plots_,
                  "write the frontier charts (frontier_psnr.png, frontier_miou.png) here (VTK)");
    c->add_option("--goal-fewer", goal_fewer_,
                  "charts: the target's times fewer Gaussians (0: no target drawn)")
        ->capture_default_str();
    c->add_option("--goal-psnr-loss", goal_psnr_, "charts: the target's largest PSNR loss in dB")
        ->capture_default_str();
    return c;
  }

  int run(const Invocation& invocation) override {
    if (!plots_.empty()) rerunUnderXvfbIfHeadless(invocation);  // before any output
    const auto runs = eval::readExperimentRuns(results_);
    const std::string text = eval::experimentTables(runs, baseline_);
    if (!out_.empty()) io::writeFileAtomically(out_, [&](std::ostream& o) { o << text; });
    std::cout << text;
    if (plots_.empty()) return 0;
#if SADSPLAT_HAVE_VIZ
    for (const std::string& path : viz::writeFrontierCharts(
             plots_, eval::frontierPoints(runs, baseline_), baseline_, {goal_fewer_, goal_psnr_})) {
      std::cout << "wrote " << path << "\n";
    }
    return 0;
#else
    throw Error(plots_, "--plots", "a build with VTK (charts)",
                "this sadsplat was built without it");
#endif
  }

 private:
  std::string results_, baseline_ = "none", out_, plots_;
  double goal_fewer_ = 12, goal_psnr_ = 0.3;
};

}  // namespace

std::unique_ptr<Command> makeTableCommand() { return std::make_unique<TableCommand>(); }

}  // namespace cli
}  // namespace sadsplat
