// `sadsplat eval RUN`: a training run's metrics on its test views.
#include <iostream>

#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/pipeline/cloud_eval.h"
#include "sadsplat/pipeline/map_products.h"
#include "sadsplat/pipeline/opened_run.h"

namespace sadsplat {
namespace cli {
namespace {

class EvalCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("eval", "Evaluate a training run on its test views");
    c->add_option("RUN", run_, "run directory")->required();
    c->add_option("--scene", scene_, "scene to evaluate on (default: the run's)");
    c->add_flag("--ortho", ortho_,
                "score the class map on the map grid instead: against the scene's "
                "ortho_truth.json (from `sadsplat synth`); writes RUN/ortho_metrics.json");
    c->add_option("--truth", truth_, "--ortho: the ground truth's JSON (default: the scene's)");
    c->add_option("--height", ortho_options_.height, "--ortho: as `ortho --height`")
        ->default_val("first");
    c->add_option("--class-from", ortho_options_.class_from, "--ortho: as `ortho --class-from`")
        ->default_val("views");
    c->add_option("--depth-tolerance", ortho_options_.depth_tolerance,
                  "--ortho: as `ortho --depth-tolerance`")
        ->default_val(0.02);
    c->add_option("--min-spread", ortho_options_.min_spread, "--ortho: as `ortho --min-spread`")
        ->default_val(0);
    c->add_option("--min-views", ortho_options_.min_views, "--ortho: as `ortho --min-views`")
        ->default_val(0);
    c->add_option("--on-surface", ortho_options_.on_surface, "--ortho: as `ortho --on-surface`")
        ->default_val(0);
    c->add_option("--raised-check", ortho_options_.raised_check,
                  "--ortho: as `ortho --raised-check`")
        ->default_val(0.33);
    c->add_option("--pit-depth", ortho_options_.pit_depth, "--ortho: as `ortho --pit-depth`")
        ->default_val(1.0);
    c->add_option("--spike-height", ortho_options_.spike_height,
                  "--ortho: as `ortho --spike-height`")
        ->default_val(0.0);
    c->add_option("--spike-clearance", ortho_options_.spike_clearance,
                  "--ortho: as `ortho --spike-clearance`")
        ->default_val(4.0);
    c->add_option("--object-step", ortho_options_.object_step,
                  "--ortho: the building objects as `ortho --object-step` cuts them")
        ->default_val(1.5);
    c->add_option("--trim", ortho_options_.trim, "--ortho: as `ortho --trim`")
        ->delimiter(',')
        ->default_val("auto");
    c->add_option("--trim-whole-under", ortho_options_.trim_whole_under,
                  "--ortho: as `ortho --trim-whole-under`")
        ->default_val(0);
    c->add_option("--ground-window", ortho_options_.ground_window,
                  "--ortho: as `ortho --ground-window`")
        ->default_val(20);
    c->add_flag("--3d", cloud_,
                "score the per-class cloud in 3D instead: every Gaussian's class against the "
                "nearest true surface of a `sadsplat synth` scene's world, distances to it, "
                "completeness; writes RUN/metrics_3d.json");
    return c;
  }
  int run(const Invocation&) override {
    if (cloud_ && ortho_) {
      throw Error("<eval>", "--3d / --ortho", "one of them per call", "both");
    }
    if (cloud_) {
      std::cout << pipeline::evalCloudRun(run_, scene_);
      return 0;
    }
    if (ortho_) {
      std::cout << pipeline::evalOrthoRun(run_, truth_, ortho_options_, scene_);
      return 0;
    }
    std::cout << pipeline::evalRun(run_, scene_);
    return 0;
  }

 private:
  std::string run_, scene_, truth_;
  pipeline::OrthoRunOptions ortho_options_;
  bool ortho_ = false;
  bool cloud_ = false;
};

}  // namespace

std::unique_ptr<Command> makeEvalCommand() { return std::make_unique<EvalCommand>(); }

}  // namespace cli
}  // namespace sadsplat
