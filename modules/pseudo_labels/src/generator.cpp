#include "sadsplat/pseudo_labels/generator.h"

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace pseudo_labels {

PseudoLabelSummary generatePseudoLabels(io::Scene& scene, TargetScorer& scorer,
                                        const PseudoLabelOptions& options,
                                        const ProgressFn& progress) {
  const int C = static_cast<int>(scene.classes.size());
  if (C < 2) throw Error(scene.source, "classes", "at least 2 classes for pseudo-labels");
  std::vector<int> views;
  for (int i = 0; i < static_cast<int>(scene.views.size()); ++i) {
    scene.views[i].pseudo = {};
    if (scene.views[i].train) views.push_back(i);
  }
  if (views.empty()) throw Error(scene.source, "split", "at least one training view");
  std::vector<ViewTargets> targets = scorer.score(scene, views, progress);
  if (targets.size() != views.size()) {
    throw Error("<pseudo-labels " + scorer.name() + ">", "scored views",
                std::to_string(views.size()), std::to_string(targets.size()));
  }

  // The statistics are taken over all targets of the training set (paper).
  std::vector<TargetMeasures> measures;
  for (const ViewTargets& t : targets) {
    for (int r = 0; r < t.segmentation.num_regions; ++r) {
      measures.push_back(
          measureTarget(&t.scores[static_cast<std::size_t>(r) * C], C, options.scale));
    }
  }
  PseudoLabelSummary summary;
  summary.backend = scorer.name();
  summary.views = static_cast<int>(views.size());
  summary.statistics = targetStatistics(measures);
  summary.targets = measures.size();
  std::size_t m = 0;
  for (std::size_t k = 0; k < views.size(); ++k) {
    io::View& v = scene.views[views[k]];
    ViewTargets& t = targets[k];
    io::ViewPseudoLabels& p = v.pseudo;
    p.backend = scorer.name();
    p.region = std::move(t.segmentation.region);
    p.num_targets = t.segmentation.num_regions;
    p.num_classes = C;
    p.scores = std::move(t.scores);
    p.feature_dim = t.feature_dim;
    p.features = std::move(t.features);
    p.kept.assign(p.num_targets, 0);
    for (int r = 0; r < p.num_targets; ++r, ++m) {
      p.kept[r] = keepTarget(measures[m], summary.statistics, options.filter_k) ? 1 : 0;
      summary.kept_targets += p.kept[r];
    }
    p.validate(scene.source + " (view " + v.name + ", backend " + scorer.name() + ")",
               static_cast<std::size_t>(v.camera.width) * v.camera.height);
  }
  return summary;
}

}  // namespace pseudo_labels
}  // namespace sadsplat
