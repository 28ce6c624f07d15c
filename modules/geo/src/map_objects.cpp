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

}  // namespace geo
}  // namespace sadsplat
