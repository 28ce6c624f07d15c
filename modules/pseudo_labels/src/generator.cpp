#include "sadsplat/pseudo_labels/generator.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/point_visibility.h"

namespace sadsplat {
namespace pseudo_labels {

TargetLayer resolveLayers(const std::vector<TargetLayer>& layers, int C,
                          const std::vector<std::vector<double>>& top1,
                          const std::vector<std::vector<std::uint8_t>>& kept,
                          std::vector<std::uint8_t>& refined_kept) {
  if (layers.empty()) throw Error("<pseudo-labels>", "target layers", "at least one layer", "none");
  const TargetLayer& base = layers[0];
  const std::size_t pixels = base.segmentation.region.size();
  for (std::size_t l = 1; l < layers.size(); ++l) {
    const Segmentation& s = layers[l].segmentation;
    if (s.width != base.segmentation.width || s.height != base.segmentation.height ||
        s.region.size() != pixels || layers[l].feature_dim != base.feature_dim) {
      throw Error("<pseudo-labels>", "target layer " + std::to_string(l),
                  "the size and feature dimension of layer 0",
                  std::to_string(s.width) + "x" + std::to_string(s.height) + ", dim " +
                      std::to_string(layers[l].feature_dim));
    }
  }

  // Common refinement, one layer at a time: a refined region is a distinct tuple of targets
  // (-1 where a layer has no target at the pixel; pixels of no target in any layer stay -1).
  std::vector<std::int32_t> refined = base.segmentation.region;
  std::vector<std::vector<int>> cover(layers.size());  // [layer][refined region] -> target|-1
  cover[0].resize(base.segmentation.num_regions);
  for (int r = 0; r < base.segmentation.num_regions; ++r) cover[0][r] = r;
  for (std::size_t l = 1; l < layers.size(); ++l) {
    const std::vector<std::int32_t>& other = layers[l].segmentation.region;
    std::unordered_map<std::int64_t, int> ids;
    std::vector<std::vector<int>> next(layers.size());
    for (std::size_t i = 0; i < pixels; ++i) {
      if (refined[i] < 0 && other[i] < 0) continue;
      const std::int64_t key = (static_cast<std::int64_t>(refined[i] + 1) << 32) | (other[i] + 1);
      auto it = ids.find(key);
      if (it == ids.end()) {
        it = ids.emplace(key, static_cast<int>(ids.size())).first;
        for (std::size_t m = 0; m < l; ++m) {
          next[m].push_back(refined[i] >= 0 ? cover[m][refined[i]] : -1);
        }
        next[l].push_back(other[i]);
      }
      refined[i] = it->second;
    }
    cover = std::move(next);
  }

  const int n = static_cast<int>(cover[0].size());
  TargetLayer out;
  out.segmentation = base.segmentation;
  out.segmentation.region = std::move(refined);
  out.segmentation.num_regions = n;
  out.feature_dim = base.feature_dim;
  out.scores.resize(static_cast<std::size_t>(n) * C);
  out.features.resize(static_cast<std::size_t>(n) * base.feature_dim);
  refined_kept.assign(n, 0);
  for (int r = 0; r < n; ++r) {
    // Default: the finest layer with a target here; then the kept target of highest TOP1.
    std::size_t layer = 0;
    while (cover[layer][r] < 0) ++layer;
    int target = cover[layer][r];
    for (std::size_t l = 0; l < layers.size(); ++l) {
      const int t = cover[l][r];
      if (t >= 0 && kept[l][t] && (!refined_kept[r] || top1[l][t] > top1[layer][target])) {
        layer = l;
        target = t;
        refined_kept[r] = 1;
      }
    }
    const TargetLayer& src = layers[layer];
    std::copy_n(src.scores.begin() + static_cast<std::ptrdiff_t>(target) * C, C,
                out.scores.begin() + static_cast<std::ptrdiff_t>(r) * C);
    std::copy_n(src.features.begin() + static_cast<std::ptrdiff_t>(target) * src.feature_dim,
                src.feature_dim,
                out.features.begin() + static_cast<std::ptrdiff_t>(r) * out.feature_dim);
  }
  return out;
}

namespace {

// Per-class agreement of the kept pseudo-labels with the ground truth of the labelled training
// views; classes below options.min_class_precision (with enough evidence) are unkept everywhere.
void checkClassReliability(io::Scene& scene, const std::vector<int>& views,
                           const PseudoLabelOptions& options, PseudoLabelSummary& summary) {
  const int C = static_cast<int>(scene.classes.size());
  summary.check_pixels.assign(C, 0);
  summary.check_correct.assign(C, 0);
  summary.class_rejected.assign(C, false);
  for (int i : views) {
    const io::View& v = scene.views[i];
    if (!v.labelled || v.labels.empty()) continue;
    const std::vector<std::int16_t> labels = v.pseudo.labelMap();
    for (std::size_t px = 0; px < labels.size(); ++px) {
      const int gt = v.labels.pixels[px];
      if (labels[px] < 0 || gt >= C) continue;
      ++summary.check_pixels[labels[px]];
      summary.check_correct[labels[px]] += gt == labels[px] ? 1 : 0;
    }
  }
  if (options.min_class_precision <= 0) return;
  for (int c = 0; c < C; ++c) {
    summary.class_rejected[c] =
        summary.check_pixels[c] >= options.min_check_pixels &&
        summary.check_correct[c] < options.min_class_precision * summary.check_pixels[c];
  }
  for (int i : views) {
    io::ViewPseudoLabels& p = scene.views[i].pseudo;
    const std::vector<std::int16_t> target_class = p.targetClasses();
    for (int t = 0; t < p.num_targets; ++t) {
      if (p.kept[t] && summary.class_rejected[target_class[t]]) p.kept[t] = 0;
    }
  }
}

}  // namespace

std::vector<std::size_t> applyViewAgreementCheck(io::Scene& scene, const std::vector<int>& views,
                                                 double min_agreement, std::size_t min_votes) {
  const int C = static_cast<int>(scene.classes.size());
  std::vector<std::size_t> removed(C, 0);
  const std::size_t P = scene.points.size();
  if (P == 0 || min_agreement <= 0) return removed;
  // votes[p * C + c]: training views whose target at point p has argmax class c.
  std::vector<std::uint32_t> votes(P * C, 0), seen_by(P, 0);
  std::vector<std::vector<PointHit>> hits(views.size());
  std::vector<std::vector<std::int16_t>> target_class(views.size());
  for (std::size_t k = 0; k < views.size(); ++k) {
    const io::View& v = scene.views[views[k]];
    if (v.pseudo.empty()) continue;
    hits[k] = visiblePoints(scene, v);
    target_class[k] = v.pseudo.targetClasses();
    for (const PointHit& h : hits[k]) {
      const int r = v.pseudo.region[h.pixel];
      if (r < 0) continue;
      ++votes[h.point * C + target_class[k][r]];
      ++seen_by[h.point];
    }
  }
  for (std::size_t k = 0; k < views.size(); ++k) {
    io::ViewPseudoLabels& p = scene.views[views[k]].pseudo;
    std::vector<std::size_t> agree(p.num_targets, 0), total(p.num_targets, 0);
    for (const PointHit& h : hits[k]) {
      const int r = p.region[h.pixel];
      if (r < 0 || !p.kept[r]) continue;
      // This view's own vote at the point is its target's class: count the other views only.
      total[r] += seen_by[h.point] - 1;
      agree[r] += votes[h.point * C + target_class[k][r]] - 1;
    }
    for (int r = 0; r < p.num_targets; ++r) {
      if (!p.kept[r] || total[r] < min_votes || agree[r] >= min_agreement * total[r]) {
        continue;
      }
      p.kept[r] = 0;
      ++removed[target_class[k][r]];
    }
  }
  return removed;
}

PseudoLabelSummary generatePseudoLabels(io::Scene& scene, TargetScorer& scorer,
                                        const PseudoLabelOptions& options,
                                        const ProgressFn& progress) {
  if (!std::isfinite(options.filter_k)) {
    throw Error("<pseudo-labels>", "filter k (--filter-k)", "a finite number",
                std::to_string(options.filter_k));
  }
  if (!(options.min_view_agreement >= 0 && options.min_view_agreement <= 1)) {
    throw Error("<pseudo-labels>", "min view agreement (--min-view-agreement)", "a share in [0, 1]",
                std::to_string(options.min_view_agreement));
  }
  if (!(options.min_class_precision >= 0 && options.min_class_precision <= 1)) {
    throw Error("<pseudo-labels>", "min class precision (--min-class-precision)",
                "a share in [0, 1]", std::to_string(options.min_class_precision));
  }
  const int C = static_cast<int>(scene.classes.size());
  if (C < 2)
    throw Error(scene.source, "classes", "at least 2 classes for pseudo-labels", std::to_string(C));
  std::vector<int> views;
  for (int i = 0; i < static_cast<int>(scene.views.size()); ++i) {
    scene.views[i].pseudo = {};
    if (scene.views[i].train) views.push_back(i);
  }
  if (views.empty()) throw Error(scene.source, "split", "at least one training view", "none");
  std::vector<ViewTargets> targets = scorer.score(scene, views, progress);
  if (targets.size() != views.size()) {
    throw Error("<pseudo-labels " + scorer.name() + ">", "scored views",
                std::to_string(views.size()), std::to_string(targets.size()));
  }

  // The statistics are taken over all targets of the training set (paper), of every layer.
  std::vector<TargetMeasures> measures;
  for (const ViewTargets& t : targets) {
    if (t.layers.empty()) {
      throw Error("<pseudo-labels " + scorer.name() + ">", "target layers", "at least one", "none");
    }
    for (const TargetLayer& layer : t.layers) {
      for (int r = 0; r < layer.segmentation.num_regions; ++r) {
        measures.push_back(
            measureTarget(&layer.scores[static_cast<std::size_t>(r) * C], C, options.scale));
      }
    }
  }
  PseudoLabelSummary summary;
  summary.backend = scorer.name();
  summary.views = static_cast<int>(views.size());
  summary.statistics = targetStatistics(measures);
  summary.targets = measures.size();
  if (options.per_class) summary.class_statistics = classStatistics(measures, C);
  std::size_t m = 0;
  for (std::size_t k = 0; k < views.size(); ++k) {
    io::View& v = scene.views[views[k]];
    const std::vector<TargetLayer>& layers = targets[k].layers;
    std::vector<std::vector<double>> top1(layers.size());
    std::vector<std::vector<std::uint8_t>> kept(layers.size());
    for (std::size_t l = 0; l < layers.size(); ++l) {
      for (int r = 0; r < layers[l].segmentation.num_regions; ++r, ++m) {
        const TargetMeasures& t = measures[m];
        const bool keep =
            keepTarget(t,
                       options.per_class && t.top_class >= 0 ? summary.class_statistics[t.top_class]
                                                             : summary.statistics,
                       options.filter_k);
        top1[l].push_back(measures[m].top1);
        kept[l].push_back(keep ? 1 : 0);
        summary.kept_targets += keep ? 1 : 0;
      }
    }
    io::ViewPseudoLabels& p = v.pseudo;
    p.backend = scorer.name();
    TargetLayer stored = resolveLayers(layers, C, top1, kept, p.kept);
    p.region = std::move(stored.segmentation.region);
    p.num_targets = stored.segmentation.num_regions;
    p.num_classes = C;
    p.scores = std::move(stored.scores);
    p.feature_dim = stored.feature_dim;
    p.features = std::move(stored.features);
    p.validate(scene.source + " (view " + v.name + ", backend " + scorer.name() + ")",
               static_cast<std::size_t>(v.camera.width) * v.camera.height);
  }
  if (options.min_view_agreement > 0) {
    summary.view_check_removed =
        applyViewAgreementCheck(scene, views, options.min_view_agreement, options.min_view_votes);
  }
  checkClassReliability(scene, views, options, summary);
  for (int i : views) {
    for (std::uint8_t k : scene.views[i].pseudo.kept) summary.kept_regions += k;
  }
  return summary;
}

}  // namespace pseudo_labels
}  // namespace sadsplat
