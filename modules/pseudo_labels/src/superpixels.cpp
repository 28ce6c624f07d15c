#include "sadsplat/pseudo_labels/superpixels.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace pseudo_labels {
namespace {

float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float labF(float t) {
  constexpr float d = 6.0f / 29.0f;
  return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0f / 29.0f;
}

struct Centre {
  float l, a, b, x, y;
};

}  // namespace

void srgbToLab(std::uint8_t r8, std::uint8_t g8, std::uint8_t b8, float lab[3]) {
  const float r = srgbToLinear(r8 / 255.0f), g = srgbToLinear(g8 / 255.0f),
              b = srgbToLinear(b8 / 255.0f);
  const float X = (0.4124f * r + 0.3576f * g + 0.1805f * b) / 0.95047f;
  const float Y = 0.2126f * r + 0.7152f * g + 0.0722f * b;
  const float Z = (0.0193f * r + 0.1192f * g + 0.9505f * b) / 1.08883f;
  const float fx = labF(X), fy = labF(Y), fz = labF(Z);
  lab[0] = 116 * fy - 16;
  lab[1] = 500 * (fx - fy);
  lab[2] = 200 * (fy - fz);
}

std::vector<float> imageToLab(const io::Image8& rgb) {
  const std::size_t N = static_cast<std::size_t>(rgb.width) * rgb.height;
  std::vector<float> lab(N * 3);
  for (std::size_t i = 0; i < N; ++i) {
    srgbToLab(rgb.pixels[3 * i], rgb.pixels[3 * i + 1], rgb.pixels[3 * i + 2], &lab[3 * i]);
  }
  return lab;
}

Segmentation slicSuperpixels(const io::Image8& rgb, const io::Image8& mask, const SlicOptions& o) {
  if (rgb.channels != 3 ||
      rgb.pixels.size() != static_cast<std::size_t>(rgb.width) * rgb.height * 3) {
    throw Error("<superpixels>", "image", "a 3-channel image",
                std::to_string(rgb.channels) + " channels");
  }
  if (!mask.empty() && (mask.width != rgb.width || mask.height != rgb.height)) {
    throw Error("<superpixels>", "mask", "the image's size",
                std::to_string(mask.width) + "x" + std::to_string(mask.height));
  }
  if (o.region_size < 2 || o.iterations < 1 || !(o.compactness > 0)) {
    throw Error("<superpixels>", "options", "region_size >= 2, iterations >= 1, compactness > 0",
                "region_size " + std::to_string(o.region_size) + ", iterations " +
                    std::to_string(o.iterations) + ", compactness " +
                    std::to_string(o.compactness));
  }
  const int W = rgb.width, H = rgb.height, S = o.region_size;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  auto valid = [&](std::size_t i) { return mask.empty() || mask.pixels[i] != 0; };
  const std::vector<float> lab = imageToLab(rgb);
  auto gradient = [&](int x, int y) {
    const auto at = [&](int xx, int yy) {
      return &lab[3 * (static_cast<std::size_t>(std::clamp(yy, 0, H - 1)) * W +
                       std::clamp(xx, 0, W - 1))];
    };
    float g = 0;
    for (int k = 0; k < 3; ++k) {
      const float dx = at(x + 1, y)[k] - at(x - 1, y)[k], dy = at(x, y + 1)[k] - at(x, y - 1)[k];
      g += dx * dx + dy * dy;
    }
    return g;
  };

  // Seeds on the grid, moved to the lowest gradient of their 3x3 neighbourhood (SLIC, step 1).
  std::vector<Centre> centres;
  for (int gy = S / 2; gy < H; gy += S) {
    for (int gx = S / 2; gx < W; gx += S) {
      int bx = gx, by = gy;
      float best = std::numeric_limits<float>::max();
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = gx + dx, y = gy + dy;
          if (x < 0 || y < 0 || x >= W || y >= H || !valid(static_cast<std::size_t>(y) * W + x))
            continue;
          const float g = gradient(x, y);
          if (g < best) best = g, bx = x, by = y;
        }
      }
      if (best == std::numeric_limits<float>::max()) continue;  // seed cell fully masked
      const float* p = &lab[3 * (static_cast<std::size_t>(by) * W + bx)];
      centres.push_back({p[0], p[1], p[2], static_cast<float>(bx), static_cast<float>(by)});
    }
  }

  std::vector<std::int32_t> assign(N, -1);
  std::vector<float> dist(N);
  const float spatial = static_cast<float>((o.compactness / S) * (o.compactness / S));
  for (int it = 0; it < o.iterations; ++it) {
    std::fill(dist.begin(), dist.end(), std::numeric_limits<float>::max());
    for (std::size_t k = 0; k < centres.size(); ++k) {
      const Centre& c = centres[k];
      const int x0 = std::max(0, static_cast<int>(c.x) - S),
                x1 = std::min(W - 1, static_cast<int>(c.x) + S);
      const int y0 = std::max(0, static_cast<int>(c.y) - S),
                y1 = std::min(H - 1, static_cast<int>(c.y) + S);
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * W + x;
          if (!valid(i)) continue;
          const float dl = lab[3 * i] - c.l, da = lab[3 * i + 1] - c.a, db = lab[3 * i + 2] - c.b;
          const float dx = x - c.x, dy = y - c.y;
          const float d = dl * dl + da * da + db * db + spatial * (dx * dx + dy * dy);
          if (d < dist[i]) dist[i] = d, assign[i] = static_cast<std::int32_t>(k);
        }
      }
    }
    std::vector<double> sum(centres.size() * 5, 0.0);
    std::vector<std::size_t> count(centres.size(), 0);
    for (std::size_t i = 0; i < N; ++i) {
      if (assign[i] < 0) continue;
      double* s = &sum[5 * assign[i]];
      s[0] += lab[3 * i], s[1] += lab[3 * i + 1], s[2] += lab[3 * i + 2];
      s[3] += static_cast<double>(i % W), s[4] += static_cast<double>(i / W);
      ++count[assign[i]];
    }
    for (std::size_t k = 0; k < centres.size(); ++k) {
      if (count[k] == 0) continue;
      const double* s = &sum[5 * k];
      centres[k] = {static_cast<float>(s[0] / count[k]), static_cast<float>(s[1] / count[k]),
                    static_cast<float>(s[2] / count[k]), static_cast<float>(s[3] / count[k]),
                    static_cast<float>(s[4] / count[k])};
    }
  }

  // Connectivity (SLIC, step 3): label 4-connected components; a component smaller than S^2 / 4
  // joins the component next to where its scan started.
  Segmentation seg;
  seg.width = W;
  seg.height = H;
  seg.region.assign(N, -1);
  const std::size_t min_size = std::max<std::size_t>(1, static_cast<std::size_t>(S) * S / 4);
  std::vector<std::size_t> stack, component;
  int next = 0;
  for (std::size_t start = 0; start < N; ++start) {
    if (assign[start] < 0 || seg.region[start] >= 0) continue;
    // The label of a neighbour that already has one (left or above), for merging a fragment.
    std::int32_t adjacent = -1;
    const int sx = static_cast<int>(start % W), sy = static_cast<int>(start / W);
    if (sx > 0 && seg.region[start - 1] >= 0)
      adjacent = seg.region[start - 1];
    else if (sy > 0 && seg.region[start - W] >= 0)
      adjacent = seg.region[start - W];
    component.clear();
    stack.assign(1, start);
    seg.region[start] = next;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      component.push_back(i);
      const int x = static_cast<int>(i % W), y = static_cast<int>(i / W);
      const std::size_t nb[4] = {i - 1, i + 1, i - W, i + W};
      const bool ok[4] = {x > 0, x + 1 < W, y > 0, y + 1 < H};
      for (int k = 0; k < 4; ++k) {
        if (ok[k] && seg.region[nb[k]] < 0 && assign[nb[k]] == assign[i]) {
          seg.region[nb[k]] = next;
          stack.push_back(nb[k]);
        }
      }
    }
    if (component.size() < min_size && adjacent >= 0) {
      for (std::size_t i : component) seg.region[i] = adjacent;
    } else {
      ++next;
    }
  }
  seg.num_regions = next;
  return seg;
}

}  // namespace pseudo_labels
}  // namespace sadsplat
