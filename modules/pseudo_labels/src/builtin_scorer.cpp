// The built-in backend: SLIC superpixels as targets, region descriptors, and a few-shot
// classifier fitted on the labelled views' regions (majority label of sufficiently pure regions).
#include <ATen/Parallel.h>

#include <map>

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
    std::vector<Segmentation> segs(all.size());
    std::vector<std::vector<float>> desc(all.size());
    std::atomic<int> done{0};
    at::parallel_for(0, static_cast<std::int64_t>(all.size()), 1,
                     [&](std::int64_t b, std::int64_t e) {
                       for (std::int64_t k = b; k < e; ++k) {
                         const io::View& v = scene.views[all[k]];
                         segs[k] = options_.targets == MaskGenerator::kGraph
                                       ? graphSegmentation(v.rgb, v.mask, options_.graph)
                                       : slicSuperpixels(v.rgb, v.mask, options_.superpixels);
                         desc[k] = regionFeatures(scene, v, segs[k], g);
                         const int n = ++done;
                         if (progress && (n % 10 == 0 || n == static_cast<int>(all.size()))) {
                           progress("superpixels + descriptors: " + std::to_string(n) + "/" +
                                    std::to_string(all.size()) + " views");
                         }
                       }
                     });

    std::vector<float> x;
    std::vector<int> y, group;
    for (std::size_t k = 0; k < all.size(); ++k) {
      const io::View& v = scene.views[all[k]];
      if (!v.labelled || v.labels.empty()) continue;
      std::vector<std::vector<int>> hist(segs[k].num_regions, std::vector<int>(C + 1, 0));
      for (std::size_t i = 0; i < segs[k].region.size(); ++i) {
        const int r = segs[k].region[i];
        if (r < 0) continue;
        const int l = v.labels.pixels[i];
        hist[r][l < C ? l : C]++;
      }
      for (int r = 0; r < segs[k].num_regions; ++r) {
        int total = 0, best = 0;
        for (int c = 0; c <= C; ++c) total += hist[r][c];
        for (int c = 1; c < C; ++c)
          if (hist[r][c] > hist[r][best]) best = c;
        if (total == 0 || hist[r][best] < options_.min_purity * total) continue;
        x.insert(x.end(), desc[k].begin() + static_cast<std::ptrdiff_t>(r) * kRegionFeatureDim,
                 desc[k].begin() + static_cast<std::ptrdiff_t>(r + 1) * kRegionFeatureDim);
        y.push_back(best);
        group.push_back(all[k]);
      }
    }
    if (y.empty()) {
      throw Error(scene.source, "labelled views",
                  "at least one labelled training view with label maps (the built-in backend's "
                  "few-shot examples)");
    }
    FewShotClassifier classifier(options_.classifier);
    classifier.fit(x, kRegionFeatureDim, y, group, C);
    if (progress) {
      progress("few-shot classifier: " + std::to_string(y.size()) + " labelled regions, " +
               (classifier.usedQuadratic() ? "quadratic" : "linear") + " features, temperature " +
               std::to_string(classifier.temperature()));
    }

    std::vector<ViewTargets> out(views.size());
    for (std::size_t k = 0; k < views.size(); ++k) {
      ViewTargets& t = out[k];
      t.segmentation = std::move(segs[k]);
      t.scores = classifier.predictProbabilities(desc[k]);
      // In the class-score space of the built-in backend a target's feature is its scores.
      t.feature_dim = C;
      t.features = t.scores;
    }
    return out;
  }

 private:
  BuiltinOptions options_;
};

}  // namespace

TargetScorer::Ptr makeBuiltinScorer(const BuiltinOptions& options) {
  return std::make_shared<BuiltinScorer>(options);
}

}  // namespace pseudo_labels
}  // namespace sadsplat
