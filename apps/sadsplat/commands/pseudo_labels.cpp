// `sadsplat pseudo-labels SCENE`: confidence maps and filtered pseudo-labels of the training
// views, written into the scene cache.
#include <iostream>

#include "commands.h"
#include "sadsplat/pipeline/pseudo_label_run.h"

namespace sadsplat {
namespace cli {
namespace {

class PseudoLabelsCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("pseudo-labels",
                                     "Write confidence maps and filtered pseudo-labels of the "
                                     "training views into the scene cache");
    auto& o = options_;
    c->add_option("SCENE", o.scene, "scene cache (updated in place) or scene directory")
        ->required();
    c->add_option("--out", o.out, "scene cache to write instead");
    c->add_option("--backend", o.backend, "builtin or torchscript")->capture_default_str();
    c->add_option("--sam", o.sam_model, "torchscript: SAM TorchScript file");
    c->add_option("--clip", o.clip_model, "torchscript: CLIP TorchScript file");
    c->add_option("--report", o.report_dir, "write report.json/.txt and overlays here");
    c->add_option("--filter-k", o.filter.filter_k, "thresholds mean + k std (paper: 1)")
        ->capture_default_str();
    c->add_option("--filter", filter_,
                  "per-class: mean + k std over the targets of each TOP1 class (class-balanced); "
                  "paper: over all targets (with --filter-k 1 --min-view-agreement 0 exactly the "
                  "paper)")
        ->check(CLI::IsMember({"per-class", "paper"}))
        ->capture_default_str();
    c->add_option("--min-class-precision", o.filter.min_class_precision,
                  "remove the pseudo-labels of a class whose kept labels agree with the labelled "
                  "views' ground truth on fewer than this share of pixels (0 = off; not the "
                  "paper)")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    c->add_option("--min-view-agreement", o.filter.min_view_agreement,
                  "unkeep a target when the other views seeing its sparse points vote for its "
                  "class less often than this (0 = off; not the paper)")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    c->add_option("--region-size", o.builtin.superpixels.region_size,
                  "builtin: superpixel size in pixels of an 800x450 view (scaled with the view's "
                  "size, at least 4; see --fixed-region-size)")
        ->capture_default_str();
    c->add_flag("--fixed-region-size", fixed_region_size_,
                "builtin: --region-size in pixels whatever the view's size");
    c->add_option("--filter-scale", scale_,
                  "TOP1/dTOP measured on the scores (paper) or as "
                  "log-odds")
        ->check(CLI::IsMember({"score", "log-odds"}))
        ->capture_default_str();
    c->add_option("--targets", targets_,
                  "builtin: mask generator, slic (equal-size superpixels), graph, or multiscale "
                  "(overlapping SLIC layers of sizes region-size x --scales)")
        ->check(CLI::IsMember({"slic", "graph", "multiscale"}))
        ->capture_default_str();
    c->add_option("--scales", o.builtin.multiscale,
                  "builtin, multiscale: ascending region-size factors")
        ->delimiter(',')
        ->capture_default_str();
    c->add_option("--graph-k", o.builtin.graph.k, "builtin, graph: merge threshold scale k")
        ->capture_default_str();
    c->add_option("--graph-min-size", o.builtin.graph.min_size,
                  "builtin, graph: smallest target in pixels")
        ->capture_default_str();
    c->add_flag("--no-geometry", no_geometry_, "builtin: do not use the sparse points' heights");
    c->add_option("--scale", o.scale, "image scale when importing a directory")
        ->capture_default_str();
    return c;
  }

  int run(const Invocation&) override {
    using pseudo_labels::MaskGenerator;
    auto& o = options_;
    o.builtin.geometry = !no_geometry_;
    o.builtin.scale_region_size = !fixed_region_size_;
    o.builtin.targets = targets_ == "graph"        ? MaskGenerator::kGraph
                        : targets_ == "multiscale" ? MaskGenerator::kSlicMultiscale
                                                   : MaskGenerator::kSlic;
    o.filter.per_class = filter_ == "per-class";
    o.filter.scale = scale_ == "log-odds" ? pseudo_labels::ScoreScale::kLogOdds
                                          : pseudo_labels::ScoreScale::kScore;
    o.progress = &std::cout;
    std::cout << pipeline::pseudoLabelRun(o);
    return 0;
  }

 private:
  pipeline::PseudoLabelRunOptions options_;
  std::string filter_ = "per-class", scale_ = "log-odds", targets_ = "slic";
  bool fixed_region_size_ = false, no_geometry_ = false;
};

}  // namespace

std::unique_ptr<Command> makePseudoLabelsCommand() {
  return std::make_unique<PseudoLabelsCommand>();
}

}  // namespace cli
}  // namespace sadsplat
