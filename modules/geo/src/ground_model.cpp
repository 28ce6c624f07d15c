#include "sadsplat/geo/ground_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/common/order_statistics.h"

namespace sadsplat {
namespace geo {
namespace {

constexpr float kNone = std::numeric_limits<float>::quiet_NaN();

void checkSize(std::size_t got, std::size_t cells, const char* field) {
  if (got != cells) {
    throw Error("<ground model>", field, std::to_string(cells) + " cells", std::to_string(got));
  }
}

// Where the pixel centres of a row (or column) of `cells` fall between the centres of windows of
// `window` cells (the last one possibly shorter): the lower window and the weight of the upper.
struct Between {
  std::vector<int> lower;
  std::vector<float> weight;
};

Between between(int cells, int window, int windows) {
  std::vector<double> centre(windows);
  for (int i = 0; i < windows; ++i) {
    centre[i] = 0.5 * (i * window + std::min(cells, (i + 1) * window));
  }
  Between b;
  b.lower.resize(cells);
  b.weight.resize(cells);
  int i = 0;
  for (int c = 0; c < cells; ++c) {
    const double x = c + 0.5;
    while (i + 1 < windows - 1 && centre[i + 1] <= x) ++i;
    if (windows == 1 || x <= centre[0]) {
      b.lower[c] = 0, b.weight[c] = 0;
    } else if (x >= centre[windows - 1]) {
      b.lower[c] = windows - 2, b.weight[c] = 1;
    } else {
      b.lower[c] = i;
      b.weight[c] = static_cast<float>((x - centre[i]) / (centre[i + 1] - centre[i]));
    }
  }
  return b;
}

// The ground-class cells with a surface and their level (GroundOutliers::level); the callers
// check the sizes.
GroundOutliers groundLevel(const std::vector<std::uint8_t>& classes,
                           const std::vector<float>& surface,
                           const std::vector<int>& ground_classes, int width, int height,
                           int window_cells, std::vector<std::uint8_t>& ground_cell) {
  std::vector<std::uint8_t> is_ground(256, 0);
  for (int c : ground_classes) is_ground.at(static_cast<std::size_t>(c)) = 1;
  ground_cell.assign(classes.size(), 0);
  for (std::size_t c = 0; c < classes.size(); ++c) {
    ground_cell[c] = is_ground[classes[c]] && std::isfinite(surface[c]);
  }
  GroundModelOptions options;
  options.window_cells = window_cells;
  options.percentile = 0.5;
  GroundOutliers out;
  out.level = groundHeights(surface, ground_cell, width, height, options);
  return out;
}

}  // namespace

std::vector<float> groundHeights(const std::vector<float>& surface,
                                 const std::vector<std::uint8_t>& covered, int width, int height,
                                 const GroundModelOptions& options) {
  if (width < 1 || height < 1) {
    throw Error("<ground model>", "grid", "width and height >= 1",
                std::to_string(width) + " x " + std::to_string(height));
  }
  const std::size_t cells = static_cast<std::size_t>(width) * height;
  checkSize(surface.size(), cells, "surface");
  checkSize(covered.size(), cells, "covered");
  if (options.window_cells < 1) {
    throw Error("<ground model>", "window", "at least 1 cell",
                std::to_string(options.window_cells));
  }
  const int win = options.window_cells;
  const int wx = (width + win - 1) / win, wy = (height + win - 1) / win;

  // A low percentile of each window's surface.
  std::vector<float> level(static_cast<std::size_t>(wx) * wy, kNone);
  std::vector<float> values;
  for (int j = 0; j < wy; ++j) {
    for (int i = 0; i < wx; ++i) {
      values.clear();
      const int x1 = std::min(width, (i + 1) * win), y1 = std::min(height, (j + 1) * win);
      for (int y = j * win; y < y1; ++y) {
        for (int x = i * win; x < x1; ++x) {
          const std::size_t c = static_cast<std::size_t>(y) * width + x;
          if (covered[c] && std::isfinite(surface[c])) values.push_back(surface[c]);
        }
      }
      const double area = static_cast<double>(x1 - i * win) * (y1 - j * win);
      if (values.empty() || values.size() < options.min_covered * area) continue;
      const std::size_t k = static_cast<std::size_t>(options.percentile * (values.size() - 1));
      std::nth_element(values.begin(), values.begin() + k, values.end());
      level[static_cast<std::size_t>(j) * wx + i] = values[k];
    }
  }
  // The median of each window with its neighbours: a window a building fills takes theirs.
  std::vector<float> smooth(level.size(), kNone);
  for (int j = 0; j < wy; ++j) {
    for (int i = 0; i < wx; ++i) {
      if (std::isnan(level[static_cast<std::size_t>(j) * wx + i])) continue;
      values.clear();
      for (int b = std::max(0, j - 1); b <= std::min(wy - 1, j + 1); ++b) {
        for (int a = std::max(0, i - 1); a <= std::min(wx - 1, i + 1); ++a) {
          const float v = level[static_cast<std::size_t>(b) * wx + a];
          if (!std::isnan(v)) values.push_back(v);
        }
      }
      smooth[static_cast<std::size_t>(j) * wx + i] = quantileInPlace(values, 0.5);
    }
  }
  // Windows without surface: the mean of their known neighbours, ring by ring.
  if (std::all_of(smooth.begin(), smooth.end(), [](float v) { return std::isnan(v); })) {
    return std::vector<float>(cells, kNone);
  }
  for (bool missing = true; missing;) {
    missing = false;
    std::vector<float> next = smooth;
    for (int j = 0; j < wy; ++j) {
      for (int i = 0; i < wx; ++i) {
        if (!std::isnan(smooth[static_cast<std::size_t>(j) * wx + i])) continue;
        double sum = 0;
        int n = 0;
        for (int b = std::max(0, j - 1); b <= std::min(wy - 1, j + 1); ++b) {
          for (int a = std::max(0, i - 1); a <= std::min(wx - 1, i + 1); ++a) {
            const float v = smooth[static_cast<std::size_t>(b) * wx + a];
            if (!std::isnan(v)) sum += v, ++n;
          }
        }
        if (n > 0) {
          next[static_cast<std::size_t>(j) * wx + i] = static_cast<float>(sum / n);
        } else {
          missing = true;
        }
      }
    }
    smooth.swap(next);
  }
  // Bilinear between the windows' centres.
  const Between bx = between(width, win, wx), by = between(height, win, wy);
  const auto at = [&](int i, int j) {
    return smooth[static_cast<std::size_t>(std::min(j, wy - 1)) * wx + std::min(i, wx - 1)];
  };
  std::vector<float> ground(cells);
  for (int y = 0; y < height; ++y) {
    const int j = by.lower[y];
    const float fy = by.weight[y];
    for (int x = 0; x < width; ++x) {
      const int i = bx.lower[x];
      const float fx = bx.weight[x];
      ground[static_cast<std::size_t>(y) * width + x] =
          (1 - fy) * ((1 - fx) * at(i, j) + fx * at(i + 1, j)) +
          fy * ((1 - fx) * at(i, j + 1) + fx * at(i + 1, j + 1));
    }
  }
  return ground;
}

std::vector<float> groundUnderPoints(const std::vector<float>& e, const std::vector<float>& n,
                                     const std::vector<float>& up,
                                     const std::vector<std::uint8_t>& use, double cell,
                                     double window) {
  checkSize(n.size(), e.size(), "n");
  checkSize(up.size(), e.size(), "up");
  checkSize(use.size(), e.size(), "use");
  if (!(cell > 0) || !(window > 0)) {
    throw Error("<ground model>", "cell / window", "> 0",
                std::to_string(cell) + " / " + std::to_string(window));
  }
  double e0 = INFINITY, e1 = -INFINITY, n0 = INFINITY, n1 = -INFINITY;
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!use[i] || !std::isfinite(e[i]) || !std::isfinite(n[i]) || !std::isfinite(up[i])) continue;
    e0 = std::min<double>(e0, e[i]), e1 = std::max<double>(e1, e[i]);
    n0 = std::min<double>(n0, n[i]), n1 = std::max<double>(n1, n[i]);
  }
  if (!(e1 >= e0)) return std::vector<float>(e.size(), kNone);
  const double w = std::floor((e1 - e0) / cell) + 1, h = std::floor((n1 - n0) / cell) + 1;
  if (w * h > 64e6) {
    throw Error(
        "<ground model>", "cell", "a grid of at most 64 million cells over the points",
        std::to_string(w) + " x " + std::to_string(h) + " cells of " + std::to_string(cell));
  }
  const int width = static_cast<int>(w), height = static_cast<int>(h);
  const auto cellOf = [&](float x, float y) {
    const int i = std::clamp(static_cast<int>(std::floor((x - e0) / cell)), 0, width - 1);
    const int j = std::clamp(static_cast<int>(std::floor((y - n0) / cell)), 0, height - 1);
    return static_cast<std::size_t>(j) * width + i;
  };
  std::vector<float> surface(static_cast<std::size_t>(width) * height, -INFINITY);
  std::vector<std::uint8_t> covered(surface.size(), 0);
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!use[i] || !std::isfinite(e[i]) || !std::isfinite(n[i]) || !std::isfinite(up[i])) continue;
    const std::size_t c = cellOf(e[i], n[i]);
    surface[c] = std::max(surface[c], up[i]);
    covered[c] = 1;
  }
  GroundModelOptions options;
  options.window_cells = std::max(1, static_cast<int>(std::lround(window / cell)));
  const std::vector<float> ground = groundHeights(surface, covered, width, height, options);
  std::vector<float> out(e.size(), kNone);
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (std::isfinite(e[i]) && std::isfinite(n[i])) out[i] = ground[cellOf(e[i], n[i])];
  }
  return out;
}

LowRaisedCells findLowRaisedCells(const std::vector<std::uint8_t>& classes,
                                  const std::vector<float>& surface,
                                  const std::vector<float>& ground, int num_classes,
                                  double raised_height, double share, double min_near_ground) {
  checkSize(surface.size(), classes.size(), "surface");
  checkSize(ground.size(), classes.size(), "ground");
  if (!(share > 0 && share <= 1)) {
    throw Error("<ground model>", "share", "a share of the class's height in (0, 1]",
                std::to_string(share));
  }
  if (!(raised_height > 0 && std::isfinite(raised_height))) {
    throw Error("<ground model>", "raised height", "a height > 0", std::to_string(raised_height));
  }
  LowRaisedCells out;
  std::vector<std::vector<float>> above(num_classes);
  for (std::size_t c = 0; c < classes.size(); ++c) {
    const float h = surface[c] - ground[c];
    if (classes[c] < num_classes && std::isfinite(h)) above[classes[c]].push_back(h);
  }
  out.median_above_ground.assign(num_classes, std::numeric_limits<double>::quiet_NaN());
  std::vector<char> raised(num_classes, 0);
  for (int k = 0; k < num_classes; ++k) {
    if (above[k].empty()) continue;
    out.median_above_ground[k] = quantileInPlace(above[k], 0.5);
    if (out.median_above_ground[k] >= raised_height) {
      raised[k] = 1;
      out.raised.push_back(k);
    }
  }
  std::size_t classified = 0, near = 0;
  for (const std::vector<float>& heights : above) {
    classified += heights.size();
    for (float h : heights) near += std::abs(h) < 0.5 * raised_height;
  }
  out.near_ground = classified ? double(near) / classified : 0.0;
  if (out.near_ground < min_near_ground) return out;
  for (int k = 0; k < num_classes; ++k) {
    if (out.median_above_ground[k] < 0.5 * raised_height) out.ground.push_back(k);
  }
  if (out.ground.empty()) {
    for (int k = 0; k < num_classes; ++k) {
      if (!raised[k] && !above[k].empty()) out.ground.push_back(k);
    }
  }
  if (out.ground.empty()) return out;  // no class for a low cell to take
  for (std::size_t c = 0; c < classes.size(); ++c) {
    const int k = classes[c];
    if (k >= num_classes || !raised[k]) continue;
    const float h = surface[c] - ground[c];
    if (std::isfinite(h) && h < share * out.median_above_ground[k]) out.cells.push_back(c);
  }
  return out;
}

GroundOutliers findGroundPits(const std::vector<std::uint8_t>& classes,
                              const std::vector<float>& surface,
                              const std::vector<int>& ground_classes, int width, int height,
                              int window_cells, double depth) {
  checkSize(surface.size(), classes.size(), "surface");
  if (!(depth > 0))
    throw Error("<ground model>", "pit depth", "a depth > 0", std::to_string(depth));
  std::vector<std::uint8_t> ground_cell;
  GroundOutliers pits =
      groundLevel(classes, surface, ground_classes, width, height, window_cells, ground_cell);
  for (std::size_t c = 0; c < classes.size(); ++c) {
    if (ground_cell[c] && surface[c] < pits.level[c] - depth) pits.cells.push_back(c);
  }
  return pits;
}

GroundOutliers findGroundSpikes(const std::vector<std::uint8_t>& classes,
                                const std::vector<float>& surface,
                                const std::vector<int>& ground_classes, int width, int height,
                                int window_cells, double rise,
                                const std::vector<int>& raised_classes, int clearance_cells) {
  checkSize(surface.size(), classes.size(), "surface");
  if (!(rise > 0))
    throw Error("<ground model>", "spike height", "a height > 0", std::to_string(rise));
  if (clearance_cells < 0) {
    throw Error("<ground model>", "spike clearance", "cells >= 0", std::to_string(clearance_cells));
  }
  std::vector<std::uint8_t> ground_cell;
  GroundOutliers spikes =
      groundLevel(classes, surface, ground_classes, width, height, window_cells, ground_cell);
  // Cells within the clearance of a raised cell: the raised cells dilated by a square (rows,
  // then columns).
  std::vector<std::uint8_t> near(classes.size(), 0);
  if (clearance_cells > 0 && !raised_classes.empty()) {
    std::vector<std::uint8_t> is_raised(256, 0);
    for (int c : raised_classes) is_raised.at(static_cast<std::size_t>(c)) = 1;
    std::vector<std::uint8_t> rows(classes.size(), 0);
    const auto at = [width](int x, int y) { return static_cast<std::size_t>(y) * width + x; };
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if (!is_raised[classes[at(x, y)]]) continue;
        for (int d = std::max(0, x - clearance_cells);
             d <= std::min(width - 1, x + clearance_cells); ++d) {
          rows[at(d, y)] = 1;
        }
      }
    }
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if (!rows[at(x, y)]) continue;
        for (int d = std::max(0, y - clearance_cells);
             d <= std::min(height - 1, y + clearance_cells); ++d) {
          near[at(x, d)] = 1;
        }
      }
    }
  }
  for (std::size_t c = 0; c < classes.size(); ++c) {
    if (ground_cell[c] && !near[c] && surface[c] > spikes.level[c] + rise) {
      spikes.cells.push_back(c);
    }
  }
  return spikes;
}

}  // namespace geo
}  // namespace sadsplat
