#include "sadsplat/pseudo_labels/quality_report.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace pseudo_labels {

PseudoLabelQuality evaluatePseudoLabels(const io::Scene& scene) {
  const int C = static_cast<int>(scene.classes.size());
  constexpr int kBins = 10;
  PseudoLabelQuality q;
  q.classes.resize(C);
  for (int c = 0; c < C; ++c) q.classes[c].name = scene.classes[c].name;
  std::vector<std::size_t> correct_of_class(C, 0), kept_of_gt_class(C, 0);
  std::vector<std::size_t> bin_pixels(kBins, 0), bin_correct(kBins, 0);
  std::vector<double> bin_score(kBins, 0);
  std::size_t correct = 0, target_pixels = 0, argmax_correct = 0;
  for (const io::View& v : scene.views) {
    if (v.pseudo.empty() || v.labels.empty() || v.labelled) continue;
    ++q.views;
    const io::ViewPseudoLabels& p = v.pseudo;
    const std::vector<std::int16_t> label = p.labelMap();
    const std::vector<std::int16_t> argmax = p.targetClasses();
    std::vector<float> top1(p.num_targets, 0);
    for (int t = 0; t < p.num_targets; ++t) {
      top1[t] = p.scores[static_cast<std::size_t>(t) * C + argmax[t]];
    }
    for (std::size_t i = 0; i < label.size(); ++i) {
      const int gt = v.labels.pixels[i];
      if (gt >= C || (!v.mask.empty() && v.mask.pixels[i] == 0)) continue;
      ++q.gt_pixels;
      ++q.classes[gt].gt_pixels;
      if (label[i] >= 0) {
        ++q.kept_pixels;
        ++kept_of_gt_class[gt];
        ++q.classes[label[i]].predicted_pixels;
        if (label[i] == gt) {
          ++correct;
          ++correct_of_class[gt];
        }
      }
      const int t = p.region[i];
      if (t >= 0) {
        ++target_pixels;
        const bool right = argmax[t] == gt;
        argmax_correct += right;
        const int b = std::min(kBins - 1, static_cast<int>(top1[t] * kBins));
        ++bin_pixels[b];
        bin_correct[b] += right;
        bin_score[b] += top1[t];
      }
    }
  }
  if (q.views == 0) {
    throw Error(
        scene.source, "views",
        "a training view with pseudo-labels and a label map that does not supervise training",
        "none");
  }
  auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  q.precision = ratio(correct, q.kept_pixels);
  q.coverage = ratio(q.kept_pixels, q.gt_pixels);
  q.argmax_accuracy = ratio(argmax_correct, target_pixels);
  for (int c = 0; c < C; ++c) {
    q.classes[c].precision = ratio(correct_of_class[c], q.classes[c].predicted_pixels);
    q.classes[c].coverage = ratio(kept_of_gt_class[c], q.classes[c].gt_pixels);
    const ClassQuality& k = q.classes[c];
    if (k.predicted_pixels >= PseudoLabelQuality::kWorstClassMinShare * q.gt_pixels &&
        k.predicted_pixels > 0 &&
        (q.worst_class < 0 || k.precision < q.classes[q.worst_class].precision)) {
      q.worst_class = c;
    }
  }
  for (int b = 0; b < kBins; ++b) {
    ReliabilityBin bin;
    bin.low = static_cast<double>(b) / kBins;
    bin.high = static_cast<double>(b + 1) / kBins;
    bin.pixels = bin_pixels[b];
    bin.accuracy = ratio(bin_correct[b], bin_pixels[b]);
    bin.mean_score = ratio(bin_score[b], bin_pixels[b]);
    q.expected_calibration_error +=
        ratio(bin_pixels[b], target_pixels) * std::abs(bin.accuracy - bin.mean_score);
    q.reliability.push_back(bin);
  }
  return q;
}

std::string PseudoLabelQuality::toJson() const {
  nlohmann::json j;
  j["views"] = views;
  j["gt_pixels"] = gt_pixels;
  j["kept_pixels"] = kept_pixels;
  j["precision"] = precision;
  j["coverage"] = coverage;
  j["argmax_accuracy"] = argmax_accuracy;
  j["expected_calibration_error"] = expected_calibration_error;
  for (const auto& c : classes) {
    j["classes"].push_back({{"name", c.name},
                            {"gt_pixels", c.gt_pixels},
                            {"predicted_pixels", c.predicted_pixels},
                            {"precision", c.precision},
                            {"coverage", c.coverage}});
  }
  if (worst_class >= 0) {
    j["worst_class"] = {{"name", classes[worst_class].name},
                        {"precision", classes[worst_class].precision},
                        {"min_share_of_labelled_pixels", kWorstClassMinShare}};
  }
  for (const auto& b : reliability) {
    j["reliability"].push_back({{"low", b.low},
                                {"high", b.high},
                                {"pixels", b.pixels},
                                {"accuracy", b.accuracy},
                                {"mean_score", b.mean_score}});
  }
  return j.dump(2) + "\n";
}

std::string PseudoLabelQuality::toText() const {
  std::ostringstream o;
  char line[256];
  std::snprintf(
      line, sizeof line,
      "pseudo-labels on %d views: precision %.2f %%, coverage %.2f %% (%zu of %zu labelled "
      "pixels); argmax accuracy before filtering %.2f %%; ECE %.3f\n",
      views, 100 * precision, 100 * coverage, kept_pixels, gt_pixels, 100 * argmax_accuracy,
      expected_calibration_error);
  o << line << "class             precision  coverage  gt share\n";
  for (const auto& c : classes) {
    std::snprintf(line, sizeof line, "%-16s %8.2f %% %8.2f %% %8.2f %%\n", c.name.c_str(),
                  100 * c.precision, 100 * c.coverage,
                  gt_pixels ? 100.0 * c.gt_pixels / gt_pixels : 0.0);
    o << line;
  }
  if (worst_class >= 0) {
    std::snprintf(line, sizeof line,
                  "worst kept class: %s %.2f %% (of the classes on >= %.2f %% of the pixels)\n",
                  classes[worst_class].name.c_str(), 100 * classes[worst_class].precision,
                  100 * kWorstClassMinShare);
    o << line;
  }
  o << "TOP1 bin     pixels  accuracy  mean TOP1\n";
  for (const auto& b : reliability) {
    std::snprintf(line, sizeof line, "[%.1f, %.1f) %9zu %8.2f %% %8.3f\n", b.low, b.high, b.pixels,
                  100 * b.accuracy, b.mean_score);
    o << line;
  }
  return o.str();
}

}  // namespace pseudo_labels
}  // namespace sadsplat
