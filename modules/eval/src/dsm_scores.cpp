#include "sadsplat/eval/dsm_scores.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/common/order_statistics.h"

namespace sadsplat {
namespace eval {
namespace {

double medianOf(std::vector<double> v) { return medianInPlace(v); }

HeightErrors summarise(const std::vector<double>& errors, const std::vector<double>& off_step) {
  HeightErrors h;
  h.cells = errors.size();
  h.off_step_cells = off_step.size();
  if (!off_step.empty()) {
    double sq = 0;
    for (double e : off_step) sq += e * e;
    h.off_step_rmse_m = std::sqrt(sq / off_step.size());
  }
  if (errors.empty()) return h;
  double sq = 0;
  std::vector<double> abs_errors(errors.size());
  for (std::size_t i = 0; i < errors.size(); ++i) {
    sq += errors[i] * errors[i];
    abs_errors[i] = std::fabs(errors[i]);
  }
  h.rmse_m = std::sqrt(sq / errors.size());
  h.median_abs_m = medianOf(abs_errors);
  const double median = medianOf(errors);
  std::vector<double> deviation(errors.size());
  for (std::size_t i = 0; i < errors.size(); ++i) deviation[i] = std::fabs(errors[i] - median);
  h.nmad_m = 1.4826 * medianOf(deviation);
  return h;
}

}  // namespace

std::vector<std::uint8_t> heightStepCells(const std::vector<float>& truth, int width, int height,
                                          double step_m) {
  std::vector<std::uint8_t> step(truth.size(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      float lo = INFINITY, hi = -INFINITY;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= width || yy >= height) continue;
          const float t = truth[static_cast<std::size_t>(yy) * width + xx];
          if (!std::isfinite(t)) continue;
          lo = std::min(lo, t), hi = std::max(hi, t);
        }
      }
      step[static_cast<std::size_t>(y) * width + x] = hi - lo > step_m ? 1 : 0;
    }
  }
  return step;
}

DsmScores scoreDsm(const std::vector<float>& model, const std::vector<float>& truth,
                   const std::vector<std::uint8_t>& classes,
                   const std::vector<std::uint8_t>& scored, int width, int height, int num_classes,
                   const DsmScoreOptions& options) {
  const std::size_t n = static_cast<std::size_t>(std::max(0, width)) * std::max(0, height);
  for (const auto& [size, what] : {std::pair<std::size_t, const char*>{model.size(), "model"},
                                   {truth.size(), "truth"},
                                   {classes.size(), "classes"},
                                   {scored.size(), "scored cells"}}) {
    if (size != n) {
      throw Error("<dsm scores>", what,
                  "one value per cell of the " + std::to_string(width) + " x " +
                      std::to_string(height) + " grid",
                  std::to_string(size));
    }
  }
  const std::vector<std::uint8_t> step = heightStepCells(truth, width, height, options.step_m);
  const std::size_t groups = static_cast<std::size_t>(std::max(0, num_classes)) + 1;
  std::vector<std::vector<double>> errors(groups), off_step(groups);
  for (std::size_t i = 0; i < n; ++i) {
    const int c = classes[i];
    if (c >= num_classes || !scored[i] || !std::isfinite(model[i]) || !std::isfinite(truth[i])) {
      continue;
    }
    const double e = double(model[i]) - truth[i];
    for (const std::size_t g : {static_cast<std::size_t>(c), groups - 1}) {
      errors[g].push_back(e);
      if (!step[i]) off_step[g].push_back(e);
    }
  }
  DsmScores s;
  s.all = summarise(errors[groups - 1], off_step[groups - 1]);
  for (std::size_t c = 0; c + 1 < groups; ++c)
    s.per_class.push_back(summarise(errors[c], off_step[c]));
  return s;
}

}  // namespace eval
}  // namespace sadsplat
