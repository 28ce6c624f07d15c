#include "sadsplat/pseudo_labels/graph_segmentation.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace pseudo_labels {
namespace {

// One pass of a separable blur of an interleaved 3-channel image (clamped borders): along x
// (step 1, extent W) or along y (step W, extent H).
void blurPass(const std::vector<float>& in, std::vector<float>& out, int W, int H,
              const std::vector<float>& kernel, bool along_x) {
  const int r = static_cast<int>(kernel.size() / 2);
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) {
        float v = 0;
        for (int i = -r; i <= r; ++i) {
          const int xx = along_x ? std::clamp(x + i, 0, W - 1) : x;
          const int yy = along_x ? y : std::clamp(y + i, 0, H - 1);
          v += kernel[i + r] * in[3 * (static_cast<std::size_t>(yy) * W + xx) + c];
        }
        out[3 * (static_cast<std::size_t>(y) * W + x) + c] = v;
      }
    }
  }
}

// Separable Gaussian blur of an interleaved 3-channel float image (clamped borders).
void gaussianBlur(std::vector<float>& img, int W, int H, double sigma) {
  if (sigma <= 0) return;
  const int r = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<float> kernel(2 * r + 1);
  float sum = 0;
  for (int i = -r; i <= r; ++i) {
    sum += kernel[i + r] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
  }
  for (float& k : kernel) k /= sum;
  std::vector<float> tmp(img.size());
  blurPass(img, tmp, W, H, kernel, true);
  blurPass(tmp, img, W, H, kernel, false);
}

struct Edge {
  float w;
  std::uint32_t a, b;
};

class Components {
 public:
  explicit Components(std::size_t n) : parent_(n), size_(n, 1), internal_(n, 0.0f) {
    std::iota(parent_.begin(), parent_.end(), 0u);
  }
  std::uint32_t find(std::uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void unite(std::uint32_t a, std::uint32_t b, float w) {  // a, b roots
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    internal_[a] = std::max({internal_[a], internal_[b], w});
  }
  std::uint32_t size(std::uint32_t root) const { return size_[root]; }
  float internal(std::uint32_t root) const { return internal_[root]; }

 private:
  std::vector<std::uint32_t> parent_, size_;
  std::vector<float> internal_;
};

}  // namespace

Segmentation graphSegmentation(const io::Image8& rgb, const io::Image8& mask,
                               const GraphSegmentationOptions& o) {
  if (rgb.channels != 3 ||
      rgb.pixels.size() != static_cast<std::size_t>(rgb.width) * rgb.height * 3) {
    throw Error("<graph segmentation>", "image", "a 3-channel image",
                std::to_string(rgb.channels) + " channels");
  }
  if (!mask.empty() && (mask.width != rgb.width || mask.height != rgb.height)) {
    throw Error("<graph segmentation>", "mask", "the image's size",
                std::to_string(mask.width) + "x" + std::to_string(mask.height));
  }
  if (!(o.k > 0) || o.min_size < 1 || !(o.sigma >= 0)) {
    throw Error("<graph segmentation>", "options", "k > 0, min_size >= 1, sigma >= 0",
                "k " + std::to_string(o.k) + ", min_size " + std::to_string(o.min_size) +
                    ", sigma " + std::to_string(o.sigma));
  }
  const int W = rgb.width, H = rgb.height;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  auto valid = [&](std::size_t i) { return mask.empty() || mask.pixels[i] != 0; };
  std::vector<float> lab = imageToLab(rgb);
  gaussianBlur(lab, W, H, o.sigma);

  std::vector<Edge> edges;
  edges.reserve(4 * N);
  auto add = [&](std::size_t i, std::size_t j) {
    if (!valid(i) || !valid(j)) return;
    float d2 = 0;
    for (int c = 0; c < 3; ++c)
      d2 += (lab[3 * i + c] - lab[3 * j + c]) * (lab[3 * i + c] - lab[3 * j + c]);
    edges.push_back({std::sqrt(d2), static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j)});
  };
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      if (x + 1 < W) add(i, i + 1);
      if (y + 1 < H) add(i, i + W);
      if (x + 1 < W && y + 1 < H) add(i, i + W + 1);
      if (x > 0 && y + 1 < H) add(i, i + W - 1);
    }
  }
  // Stable order (ties by pixel ids) so the result does not depend on the sort implementation.
  std::sort(edges.begin(), edges.end(), [](const Edge& p, const Edge& q) {
    return p.w != q.w ? p.w < q.w : (p.a != q.a ? p.a < q.a : p.b < q.b);
  });

  Components comp(N);
  const float k = static_cast<float>(o.k);
  for (const Edge& e : edges) {
    const std::uint32_t a = comp.find(e.a), b = comp.find(e.b);
    if (a == b) continue;
    if (e.w <= comp.internal(a) + k / comp.size(a) && e.w <= comp.internal(b) + k / comp.size(b))
      comp.unite(a, b, e.w);
  }
  for (const Edge& e : edges) {  // small components join their lightest neighbour
    const std::uint32_t a = comp.find(e.a), b = comp.find(e.b);
    if (a != b && (comp.size(a) < static_cast<std::uint32_t>(o.min_size) ||
                   comp.size(b) < static_cast<std::uint32_t>(o.min_size))) {
      comp.unite(a, b, e.w);
    }
  }

  Segmentation seg;
  seg.width = W;
  seg.height = H;
  seg.region.assign(N, -1);
  std::vector<std::int32_t> id(N, -1);
  for (std::size_t i = 0; i < N; ++i) {
    if (!valid(i)) continue;
    const std::uint32_t r = comp.find(static_cast<std::uint32_t>(i));
    if (id[r] < 0) id[r] = seg.num_regions++;
    seg.region[i] = id[r];
  }
  return seg;
}

}  // namespace pseudo_labels
}  // namespace sadsplat
