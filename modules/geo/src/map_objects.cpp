#include "sadsplat/geo/map_objects.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <utility>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace geo {
namespace {

bool joined(const std::vector<float>& heights, double max_step, std::size_t a, std::size_t b) {
  if (max_step <= 0) return true;
  const float ha = heights[a], hb = heights[b];
  const bool fa = std::isfinite(ha), fb = std::isfinite(hb);
  if (!fa || !fb) return fa == fb;
  return std::abs(double(ha) - double(hb)) <= max_step;
}

// The 8-connected components of the mask under `joined`, 1..n in row-major order.
std::vector<int> segments(const std::vector<std::uint8_t>& mask, const std::vector<float>& heights,
                          int width, int height, double max_step, int* count) {
  std::vector<int> label(mask.size(), 0);
  std::vector<std::size_t> stack;
  int next = 0;
  for (std::size_t start = 0; start < mask.size(); ++start) {
    if (!mask[start] || label[start]) continue;
    label[start] = ++next;
    stack.push_back(start);
    while (!stack.empty()) {
      const std::size_t k = stack.back();
      stack.pop_back();
      const int x = static_cast<int>(k % width), y = static_cast<int>(k / width);
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          const std::size_t n = static_cast<std::size_t>(ny) * width + nx;
          if (mask[n] && !label[n] && joined(heights, max_step, k, n)) {
            label[n] = next;
            stack.push_back(n);
          }
        }
      }
    }
  }
  *count = next;
  return label;
}

int root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// Merges objects under min_cells into the neighbour they share the most 8-neighbour cell pairs
// with (ties: the larger neighbour, then the lower label), the smallest first, until none is
// left that has a neighbour; then renumbers 1..n in row-major order of the first cell.
void mergeSmall(std::vector<int>& label, int width, int height, int count, std::size_t min_cells) {
  std::vector<int> parent(count + 1);
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::size_t> area(count + 1, 0);
  for (int l : label) ++area[l];
  for (bool merged = true; merged;) {
    merged = false;
    // Shared borders between the current objects (each unordered cell pair once).
    std::map<std::pair<int, int>, std::size_t> border;
    constexpr int kHalf[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const int a = label[static_cast<std::size_t>(y) * width + x];
        if (!a) continue;
        const int ra = root(parent, a);
        for (const auto& d : kHalf) {
          const int nx = x + d[0], ny = y + d[1];
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          const int b = label[static_cast<std::size_t>(ny) * width + nx];
          if (!b) continue;
          const int rb = root(parent, b);
          if (ra == rb) continue;
          ++border[{ra, rb}];
          ++border[{rb, ra}];
        }
      }
    }
    std::vector<int> best(count + 1, 0);
    std::vector<std::size_t> best_border(count + 1, 0);
    for (const auto& [pair, shared] : border) {
      const auto [a, b] = pair;
      if (area[a] >= min_cells) continue;
      const int c = best[a];
      if (!c || shared > best_border[a] || (shared == best_border[a] && area[b] > area[c])) {
        best[a] = b;
        best_border[a] = shared;
      }
    }
    std::vector<int> small;
    for (int a = 1; a <= count; ++a) {
      if (best[a]) small.push_back(a);
    }
    std::stable_sort(small.begin(), small.end(), [&](int a, int b) { return area[a] < area[b]; });
    for (const int a : small) {
      const int ra = root(parent, a), rb = root(parent, best[a]);
      if (ra == rb || area[ra] >= min_cells) continue;  // grown by an earlier merge this pass
      parent[ra] = rb;
      area[rb] += area[ra];
      area[ra] = 0;
      merged = true;
    }
  }
  std::vector<int> renumbered(count + 1, 0);
  int next = 0;
  for (int& l : label) {
    if (!l) continue;
    const int r = root(parent, l);
    if (!renumbered[r]) renumbered[r] = ++next;
    l = renumbered[r];
  }
}

}  // namespace

std::vector<int> mapObjects(const std::vector<std::uint8_t>& mask,
                            const std::vector<float>& heights, int width, int height,
                            const MapObjectOptions& options) {
  if (width < 0 || height < 0 ||
      mask.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw Error("<map objects>", "mask",
                std::to_string(width) + " x " + std::to_string(height) + " cells",
                std::to_string(mask.size()) + " cells");
  }
  if (!(options.max_step >= 0)) {
    throw Error("<map objects>", "max_step", "a height step >= 0 (metres)",
                std::to_string(options.max_step));
  }
  if (options.max_step > 0 && heights.size() != mask.size()) {
    throw Error("<map objects>", "heights",
                "one height per cell (" + std::to_string(mask.size()) + ")",
                std::to_string(heights.size()));
  }
  int count = 0;
  std::vector<int> label = segments(mask, heights, width, height, options.max_step, &count);
  if (options.min_cells > 1 && count > 1)
    mergeSmall(label, width, height, count, options.min_cells);
  return label;
}

std::vector<std::size_t> cellsOutsideHulls(
    const std::vector<int>& labels, int width,
    const std::vector<std::vector<std::array<double, 2>>>& hulls) {
  std::vector<std::size_t> outside;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const int label = labels[i];
    if (label <= 0) continue;
    if (static_cast<std::size_t>(label) > hulls.size()) {
      throw Error("<map objects>", "hulls", "a polygon for every object",
                  "none for object " + std::to_string(label));
    }
    const std::vector<std::array<double, 2>>& hull = hulls[static_cast<std::size_t>(label) - 1];
    if (hull.size() < 3) continue;
    const double x = static_cast<double>(i % width) + 0.5;
    const double y = static_cast<double>(i / width) + 0.5;
    // Inside a convex polygon: on one side of every edge (or on it).
    bool left = true, right = true;
    for (std::size_t e = 0; e < hull.size(); ++e) {
      const auto& a = hull[e];
      const auto& b = hull[(e + 1) % hull.size()];
      const double cross = (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
      left = left && cross >= -1e-9;
      right = right && cross <= 1e-9;
    }
    if (!left && !right) outside.push_back(i);
  }
  return outside;
}

std::vector<std::size_t> takeClassAround(std::vector<std::uint8_t>& classes,
                                         const std::vector<std::uint8_t>& covered, int width,
                                         int height, const std::vector<std::size_t>& cells,
                                         const std::vector<std::uint8_t>& allowed, int radius) {
  const std::size_t n = static_cast<std::size_t>(width) * height;
  if (classes.size() != n || covered.size() != n) {
    throw Error("<map objects>", "classes", std::to_string(n) + " cells",
                std::to_string(classes.size()) + " classes, " + std::to_string(covered.size()) +
                    " covered");
  }
  std::vector<std::uint8_t> taken(n, 0);
  for (const std::size_t c : cells) taken.at(c) = 1;
  std::vector<std::uint8_t> result(cells.size(), 255);
  std::vector<std::int64_t> votes(256);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const int x = static_cast<int>(cells[k] % width), y = static_cast<int>(cells[k] / width);
    std::fill(votes.begin(), votes.end(), 0);
    for (int yy = std::max(0, y - radius); yy <= std::min(height - 1, y + radius); ++yy) {
      for (int xx = std::max(0, x - radius); xx <= std::min(width - 1, x + radius); ++xx) {
        const std::size_t d = static_cast<std::size_t>(yy) * width + xx;
        const std::uint8_t c = classes[d];
        if (covered[d] && !taken[d] && c < allowed.size() && allowed[c]) ++votes[c];
      }
    }
    const auto best = std::max_element(votes.begin(), votes.end());
    if (*best > 0) result[k] = static_cast<std::uint8_t>(best - votes.begin());
  }
  // Set after the votes: a cell's new class does not vote for its neighbours.
  std::vector<std::size_t> alone;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (result[k] == 255) {
      alone.push_back(cells[k]);
    } else {
      classes[cells[k]] = result[k];
    }
  }
  return alone;
}

}  // namespace geo
}  // namespace sadsplat
