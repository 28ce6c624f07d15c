#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {

std::vector<std::int16_t> ViewPseudoLabels::targetClasses() const {
  std::vector<std::int16_t> out(num_targets, 0);
  for (int t = 0; t < num_targets; ++t) {
    const float* row = &scores[static_cast<std::size_t>(t) * num_classes];
    int best = 0;
    for (int c = 1; c < num_classes; ++c) {
      if (row[c] > row[best]) best = c;
    }
    out[t] = static_cast<std::int16_t>(best);
  }
  return out;
}

std::vector<std::int16_t> ViewPseudoLabels::labelMap() const {
  const std::vector<std::int16_t> target_class = targetClasses();
  std::vector<std::int16_t> out(region.size(), -1);
  for (std::size_t i = 0; i < region.size(); ++i) {
    if (region[i] >= 0 && kept[region[i]]) out[i] = target_class[region[i]];
  }
  return out;
}

std::vector<float> ViewPseudoLabels::maxScoreMap() const {
  std::vector<float> target_max(num_targets, 0.0f);
  for (int t = 0; t < num_targets; ++t) {
    const float* row = &scores[static_cast<std::size_t>(t) * num_classes];
    for (int c = 0; c < num_classes; ++c) target_max[t] = std::max(target_max[t], row[c]);
  }
  std::vector<float> out(region.size(), 0.0f);
  for (std::size_t i = 0; i < region.size(); ++i) {
    if (region[i] >= 0) out[i] = target_max[region[i]];
  }
  return out;
}

std::vector<float> ViewPseudoLabels::confidenceMap() const {
  std::vector<float> out(region.size() * num_classes, 0.0f);
  for (std::size_t i = 0; i < region.size(); ++i) {
    if (region[i] < 0) continue;
    const float* row = &scores[static_cast<std::size_t>(region[i]) * num_classes];
    std::copy(row, row + num_classes, out.begin() + i * num_classes);
  }
  return out;
}

void ViewPseudoLabels::validate(const std::string& origin, std::size_t pixels) const {
  if (region.size() != pixels) {
    throw Error(origin, "pseudo-labels region map", std::to_string(pixels) + " pixels",
                std::to_string(region.size()));
  }
  if (num_targets < 0 || num_classes < 1 || feature_dim < 0 ||
      scores.size() != static_cast<std::size_t>(num_targets) * num_classes ||
      features.size() != static_cast<std::size_t>(num_targets) * feature_dim ||
      kept.size() != static_cast<std::size_t>(num_targets)) {
    throw Error(origin, "pseudo-labels tables",
                "num_targets x num_classes scores, num_targets x feature_dim features, "
                "num_targets kept flags",
                std::to_string(scores.size()) + " scores, " + std::to_string(features.size()) +
                    " features, " + std::to_string(kept.size()) + " flags for " +
                    std::to_string(num_targets) + " targets");
  }
  for (std::size_t i = 0; i < region.size(); ++i) {
    if (region[i] < -1 || region[i] >= num_targets) {
      throw Error(origin, "pseudo-labels region pixel " + std::to_string(i),
                  "-1 or a target id below " + std::to_string(num_targets),
                  std::to_string(region[i]));
    }
  }
  for (float s : scores) {
    if (!(s >= 0.0f && s <= 1.0f)) {
      throw Error(origin, "pseudo-labels scores", "values in [0, 1]", std::to_string(s));
    }
  }
  for (float f : features) {
    if (!std::isfinite(f)) {
      throw Error(origin, "pseudo-labels features", "finite values", std::to_string(f));
    }
  }
}

std::vector<std::int16_t> supervisionLabels(const View& view, bool use_pseudo) {
  const std::size_t n = static_cast<std::size_t>(view.camera.width) * view.camera.height;
  std::vector<std::int16_t> out(n, -1);
  if (view.labelled && !view.labels.empty()) {
    for (std::size_t i = 0; i < n; ++i) {
      if (view.labels.pixels[i] != kIgnoreLabel) out[i] = view.labels.pixels[i];
    }
  } else if (use_pseudo && !view.pseudo.empty()) {
    out = view.pseudo.labelMap();
  }
  if (!view.mask.empty()) {
    for (std::size_t i = 0; i < n; ++i) {
      if (view.mask.pixels[i] == 0) out[i] = -1;
    }
  }
  return out;
}

std::vector<std::int64_t> annotatedPixelsPerClass(const Scene& scene, int* views) {
  std::vector<std::int64_t> pixels(scene.classes.size(), 0);
  int counted = 0;
  for (const View& v : scene.views) {
    if (!v.train || !v.labelled || v.labels.empty()) continue;
    ++counted;
    for (std::uint8_t c : v.labels.pixels) {
      if (c < pixels.size()) ++pixels[c];
    }
  }
  if (views != nullptr) *views = counted;
  return pixels;
}

}  // namespace io
}  // namespace sadsplat
