#include "sadsplat/viz/experiment_charts.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/viz/chart_png.h"

namespace sadsplat {
namespace viz {
namespace {

constexpr std::array<std::array<std::uint8_t, 3>, 8> kPalette = {{{31, 119, 180},
                                                                  {255, 127, 14},
                                                                  {44, 160, 44},
                                                                  {214, 39, 40},
                                                                  {148, 103, 189},
                                                                  {140, 86, 75},
                                                                  {227, 119, 194},
                                                                  {188, 189, 34}}};

// One series of points per configuration (the baseline first), y taken by `change`.
template <typename Change>
std::vector<ChartSeries> configurationSeries(const std::vector<eval::FrontierPoint>& points,
                                             const std::string& baseline, Change change) {
  std::vector<std::string> configs = {baseline};
  for (const auto& p : points) {
    if (std::find(configs.begin(), configs.end(), p.config) == configs.end()) {
      configs.push_back(p.config);
    }
  }
  std::vector<ChartSeries> series;
  for (std::size_t k = 0; k < configs.size(); ++k) {
    ChartSeries s;
    s.name = configs[k];
    s.color = kPalette[k % kPalette.size()];
    s.markers_only = true;
    for (const auto& p : points) {
      if (p.config != configs[k]) continue;
      s.x.push_back(p.fewer);
      s.y.push_back(change(p));
    }
    if (!s.x.empty()) series.push_back(s);
  }
  return series;
}

// The target region's border: from the right along y = floor to x = fewer, then up.
ChartSeries goalBorder(const std::vector<ChartSeries>& series, double fewer, double floor) {
  double x_max = fewer, y_max = floor;
  for (const auto& s : series) {
    for (double x : s.x) x_max = std::max(x_max, x);
    for (double y : s.y) y_max = std::max(y_max, y);
  }
  ChartSeries border;
  border.name = "goal";
  border.color = {150, 150, 150};
  // Past the last point by a quarter: the legend (top right) then covers no point and leaves the
  // border's corner in sight.
  border.x = {x_max * 1.3, fewer, fewer};
  border.y = {floor, floor, y_max + 0.5};
  return border;
}

}  // namespace

std::vector<std::string> writeFrontierCharts(const std::string& dir,
                                             const std::vector<eval::FrontierPoint>& points,
                                             const std::string& baseline,
                                             const FrontierGoal& goal) {
  if (points.empty()) {
    throw Error(dir, "frontier", "runs of the baseline configuration '" + baseline + "'",
                "no scene has any");
  }
  io::makeDirectory(dir);
  const std::string x_label = "times fewer Gaussians than " + baseline;
  std::vector<ChartSeries> psnr = configurationSeries(
      points, baseline, [](const eval::FrontierPoint& p) { return p.psnr_change; });
  std::vector<ChartSeries> miou = configurationSeries(
      points, baseline, [](const eval::FrontierPoint& p) { return p.miou_change; });
  if (goal.goal_fewer > 0) {
    psnr.push_back(goalBorder(psnr, goal.goal_fewer, -goal.goal_psnr_loss));
    miou.push_back(goalBorder(miou, goal.goal_fewer, 0));
  }
  const std::string psnr_path = dir + "/frontier_psnr.png", miou_path = dir + "/frontier_miou.png";
  writeLineChart(psnr_path,
                 {"PSNR against " + baseline + " (one point per scene, mean over training seeds)",
                  x_label, "PSNR change (dB)", 900, 550, false},
                 psnr);
  writeLineChart(miou_path,
                 {"mIoU against " + baseline + " (one point per scene, mean over training seeds)",
                  x_label, "mIoU change (points)", 900, 550, false},
                 miou);
  return {psnr_path, miou_path};
}

}  // namespace viz
}  // namespace sadsplat
