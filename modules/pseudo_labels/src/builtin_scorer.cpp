// The built-in backend: SLIC superpixels (one or several sizes) or graph segments as targets,
// region descriptors, and a few-shot classifier fitted on the labelled views' regions (majority
// label of sufficiently pure regions, of every layer).
#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/generator.h"
#include "sadsplat/pseudo_labels/region_features.h"

namespace sadsplat {
namespace pseudo_labels {
namespace {

class BuiltinScorer : public TargetScorer {
 public:
  explicit BuiltinScorer(const BuiltinOptions& o) : options_(o) {}
  std::string name() const override { return "builtin"; }

  std::vector<ViewTargets> score(const io::Scene& scene, const std::vector<int>& views,
                                 const ProgressFn& progress) override {
    const int C = static_cast<int>(scene.classes.size());
    const SceneGeometry geometry = SceneGeometry::fromScene(scene);
    const SceneGeometry* g = options_.geometry && !scene.points.empty() ? &geometry : nullptr;

    // Targets and descriptors of the views to score and of the labelled views (the training set
    // of the classifier), computed once each, in parallel over views.
    std::vector<int> all = views;
    for (int i = 0; i < static_cast<int>(scene.views.size()); ++i) {
      const io::View& v = scene.views[i];
      if (v.labelled && !v.labels.empty() && std::find(all.begin(), all.end(), i) == all.end())
        all.push_back(i);
    }
    const std::vector<Segmenter> layers = segmenters();
    std::vector<std::vector<Segmentation>> segs(all.size());        // [view][layer]
    std::vector<std::vector<std::vector<float>>> desc(all.size());  // [view][layer]
    std::atomic<int> done{0};
    at::parallel_for(0, static_cast<std::int64_t>(all.size()), 1,
                     [&](std::int64_t b, std::int64_t e) {
                       for (std::int64_t k = b; k < e; ++k) {
                         const io::View& v = scene.views[all[k]];
                         for (const Segmenter& segment : layers) {
                           segs[k].push_back(segment(v));
                           desc[k].push_back(regionFeatures(scene, v, segs[k].back(), g));
                         }
                         const int n = ++done;
                         if (progress && (n % 10 == 0 || n == static_cast<int>(all.size()))) {
                           progress("targets + descriptors: " + std::to_string(n) + "/" +
                                    std::to_string(all.size()) + " views");
                         }
                       }
                     });

    std::vector<float> x;
    std::vector<int> y, group;
    for (std::size_t k = 0; k < all.size(); ++k) {
      const io::View& v = scene.views[all[k]];
      if (!v.labelled || v.labels.empty()) continue;
      for (std::size_t l = 0; l < layers.size(); ++l) {
        addLabelledRegions(v, segs[k][l], desc[k][l], C, all[k], x, y, group);
      }
    }
    if (y.empty()) {
      throw Error(scene.source, "labelled views",
                  "at least one labelled training view with label maps (the built-in backend's "
                  "few-shot examples)",
                  "none");
    }
    FewShotClassifier classifier(options_.classifier);
    classifier.fit(x, kRegionFeatureDim, y, group, C);
    if (progress) {
      progress("few-shot classifier: " + std::to_string(y.size()) + " labelled regions, " +
               (classifier.usedQuadratic() ? "quadratic" : "linear") + " features, temperature " +
               std::to_string(classifier.temperature()));
    }

    // A labelled view is scored by a classifier fitted without it (when another labelled view
    // exists), so that its scores, like those of the unlabelled views, are held out: the filter's
    // statistics and the per-class reliability check then see the scorer as it is elsewhere.
    std::map<int, FewShotClassifier> held_out;
    const std::set<int> groups(group.begin(), group.end());
    for (std::size_t k = 0; k < views.size() && groups.size() >= 2; ++k) {
      if (!groups.count(views[k])) continue;
      std::vector<float> xo;
      std::vector<int> yo, go;
      for (std::size_t i = 0; i < y.size(); ++i) {
        if (group[i] == views[k]) continue;
        xo.insert(xo.end(), x.begin() + static_cast<std::ptrdiff_t>(i) * kRegionFeatureDim,
                  x.begin() + static_cast<std::ptrdiff_t>(i + 1) * kRegionFeatureDim);
        yo.push_back(y[i]);
        go.push_back(group[i]);
      }
      held_out.emplace(views[k], FewShotClassifier(options_.classifier))
          .first->second.fit(xo, kRegionFeatureDim, yo, go, C);
    }

    std::vector<ViewTargets> out(views.size());
    for (std::size_t k = 0; k < views.size(); ++k) {
      const auto own = held_out.find(views[k]);
      const FewShotClassifier& scorer = own != held_out.end() ? own->second : classifier;
      for (std::size_t l = 0; l < layers.size(); ++l) {
        TargetLayer t;
        t.segmentation = std::move(segs[k][l]);
        t.scores = scorer.predictProbabilities(desc[k][l]);
        // In the class-score space of the built-in backend a target's feature is its scores.
        t.feature_dim = C;
        t.features = t.scores;
        out[k].layers.push_back(std::move(t));
      }
    }
    return out;
  }

 private:
  using Segmenter = std::function<Segmentation(const io::View&)>;

  /// The mask generator of each layer (finest first).
  std::vector<Segmenter> segmenters() const {
    std::vector<Segmenter> out;
    if (options_.targets == MaskGenerator::kGraph) {
      const GraphSegmentationOptions o = options_.graph;
      out.push_back([o](const io::View& v) { return graphSegmentation(v.rgb, v.mask, o); });
      return out;
    }
    std::vector<int> factors{1};
    if (options_.targets == MaskGenerator::kSlicMultiscale) factors = options_.multiscale;
    for (std::size_t i = 0; i < factors.size(); ++i) {
      if (factors[i] < 1 || (i > 0 && factors[i] <= factors[i - 1])) {
        throw Error("<pseudo-labels builtin>", "multiscale factors (--scales)",
                    "ascending integers >= 1, e.g. 1,2,4", std::to_string(factors[i]));
      }
      const SlicOptions o = options_.superpixels;
      const bool scaled = options_.scale_region_size;
      const int factor = factors[i];
      out.push_back([o, scaled, factor](const io::View& v) {
        SlicOptions view_options = o;
        // The layers keep their size ratios: the finest size is scaled, then multiplied.
        if (scaled)
          view_options.region_size = scaledRegionSize(o.region_size, v.rgb.width, v.rgb.height);
        view_options.region_size *= factor;
        return slicSuperpixels(v.rgb, v.mask, view_options);
      });
    }
    return out;
  }

  /// Appends the regions of a labelled view whose majority label covers at least min_purity of
  /// their labelled pixels (ignore pixels count against purity) as classifier examples.
  void addLabelledRegions(const io::View& v, const Segmentation& seg,
                          const std::vector<float>& desc, int C, int view_index,
                          std::vector<float>& x, std::vector<int>& y,
                          std::vector<int>& group) const {
    std::vector<std::vector<int>> hist(seg.num_regions, std::vector<int>(C + 1, 0));
    for (std::size_t i = 0; i < seg.region.size(); ++i) {
      const int r = seg.region[i];
      if (r < 0) continue;
      const int l = v.labels.pixels[i];
      hist[r][l < C ? l : C]++;
    }
    for (int r = 0; r < seg.num_regions; ++r) {
      int total = 0, best = 0;
      for (int c = 0; c <= C; ++c) total += hist[r][c];
      for (int c = 1; c < C; ++c)
        if (hist[r][c] > hist[r][best]) best = c;
      if (total == 0 || hist[r][best] < options_.min_purity * total) continue;
      x.insert(x.end(), desc.begin() + static_cast<std::ptrdiff_t>(r) * kRegionFeatureDim,
               desc.begin() + static_cast<std::ptrdiff_t>(r + 1) * kRegionFeatureDim);
      y.push_back(best);
      group.push_back(view_index);
    }
  }

  BuiltinOptions options_;
};

}  // namespace

int scaledRegionSize(int region_size, int width, int height) {
  const double factor = std::sqrt(static_cast<double>(width) * height / (800.0 * 450.0));
  return std::max(4, static_cast<int>(std::lround(region_size * factor)));
}

TargetScorer::Ptr makeBuiltinScorer(const BuiltinOptions& options) {
  return std::make_shared<BuiltinScorer>(options);
}

}  // namespace pseudo_labels
}  // namespace sadsplat
