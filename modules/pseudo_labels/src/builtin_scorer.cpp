// The built-in backend: SLIC superpixels (one or several sizes) or graph segments as targets,
// region descriptors, and a few-shot classifier fitted on the labelled views' regions (majority
// label of sufficiently pure regions, of every layer).
#include <ATen/Parallel.h>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>

#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/generator.h"
#include "sadsplat/pseudo_labels/region_features.h"

namespace sadsplat {
namespace pseudo_labels {
namespace {

// Object-level targets from a fine partition: adjacent regions with the same most likely class
// whose colours (CIELab means) differ by at most `max_delta_e` are merged, most similar pairs
// first, comparing the merged components' mean colours. Only components of two or more regions
// become targets (the others would repeat a fine target); their pixels are -1 otherwise.
Segmentation mergeAgreeingRegions(const Segmentation& fine, const std::vector<float>& desc,
                                  const std::vector<float>& probs, int C, double max_delta_e) {
  const int n = fine.num_regions;
  std::vector<int> cls(n, 0), size(n, 0);
  std::vector<std::array<double, 3>> lab(n);
  for (int r = 0; r < n; ++r) {
    const float* p = &probs[static_cast<std::size_t>(r) * C];
    cls[r] = static_cast<int>(std::max_element(p, p + C) - p);
    for (int c = 0; c < 3; ++c)
      lab[r][c] = 100.0 * desc[static_cast<std::size_t>(r) * kRegionFeatureDim + c];
  }
  for (std::int32_t r : fine.region)
    if (r >= 0) ++size[r];
  std::vector<std::pair<int, int>> pairs;
  const int W = fine.width, H = fine.height;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const int a = fine.region[static_cast<std::size_t>(y) * W + x];
      if (a < 0) continue;
      const int right = x + 1 < W ? fine.region[static_cast<std::size_t>(y) * W + x + 1] : -1;
      const int down = y + 1 < H ? fine.region[static_cast<std::size_t>(y + 1) * W + x] : -1;
      for (int b : {right, down}) {
        if (b >= 0 && b != a && cls[a] == cls[b])
          pairs.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  auto dist = [&](int a, int b) {
    double d = 0;
    for (int c = 0; c < 3; ++c) d += (lab[a][c] - lab[b][c]) * (lab[a][c] - lab[b][c]);
    return std::sqrt(d);
  };
  std::sort(pairs.begin(), pairs.end(), [&](const auto& p, const auto& q) {
    return dist(p.first, p.second) < dist(q.first, q.second);
  });
  std::vector<int> parent(n), members(n, 1);
  std::iota(parent.begin(), parent.end(), 0);
  std::function<int(int)> find = [&](int a) {
    return parent[a] == a ? a : parent[a] = find(parent[a]);
  };
  for (const auto& [a0, b0] : pairs) {
    const int a = find(a0), b = find(b0);
    if (a == b || dist(a, b) > max_delta_e) continue;
    const double wa = size[a], wb = size[b];
    for (int c = 0; c < 3; ++c) lab[a][c] = (wa * lab[a][c] + wb * lab[b][c]) / (wa + wb);
    size[a] += size[b];
    members[a] += members[b];
    parent[b] = a;
  }
  Segmentation out;
  out.width = W;
  out.height = H;
  std::vector<int> id(n, -1);
  for (int r = 0; r < n; ++r) {
    const int root = find(r);
    if (members[root] >= 2 && id[root] < 0) id[root] = out.num_regions++;
  }
  out.region.resize(fine.region.size(), -1);
  for (std::size_t i = 0; i < fine.region.size(); ++i) {
    if (fine.region[i] >= 0) out.region[i] = id[find(fine.region[i])];
  }
  return out;
}

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
      for (std::size_t l = 0; l < layers.size(); ++l) {
        TargetLayer t;
        t.segmentation = std::move(segs[k][l]);
        t.scores = classifier.predictProbabilities(desc[k][l]);
        // In the class-score space of the built-in backend a target's feature is its scores.
        t.feature_dim = C;
        t.features = t.scores;
        out[k].layers.push_back(std::move(t));
      }
      if (options_.object_delta_e > 0) {
        const io::View& v = scene.views[views[k]];
        TargetLayer t;
        t.segmentation = mergeAgreeingRegions(out[k].layers[0].segmentation, desc[k][0],
                                              out[k].layers[0].scores, C, options_.object_delta_e);
        t.scores = classifier.predictProbabilities(regionFeatures(scene, v, t.segmentation, g));
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
        throw Error("<pseudo-labels builtin>", "multiscale factors",
                    "ascending integers >= 1, e.g. 1,2,4");
      }
      SlicOptions o = options_.superpixels;
      o.region_size *= factors[i];
      out.push_back([o](const io::View& v) { return slicSuperpixels(v.rgb, v.mask, o); });
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

TargetScorer::Ptr makeBuiltinScorer(const BuiltinOptions& options) {
  return std::make_shared<BuiltinScorer>(options);
}

}  // namespace pseudo_labels
}  // namespace sadsplat
