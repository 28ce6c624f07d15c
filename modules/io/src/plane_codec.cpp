#include "plane_codec.h"

#include <algorithm>
#include <cstring>

#include "compression.h"

namespace sadsplat {
namespace io {
namespace planes {
namespace {

// zlib level 6 (for images the level hardly matters: Huffman coding only).
constexpr int kLevel = 6;

// MED: min(left, up) if up_left >= max, max(left, up) if up_left <= min, else the gradient
// left + up - up_left; which is the gradient clamped to [min, max] (no branch to mispredict).
inline int medPrediction(int left, int up, int up_left) {
  const int lo = std::min(left, up), hi = std::max(left, up);
  return std::clamp(left + up - up_left, lo, hi);
}

// The MED prediction of pixel (x, y) of plane `p` (row-major, `w` wide) from decoded neighbours;
// outside the image the neighbours are 0.
inline int predict(const std::uint8_t* p, int w, int x, int y) {
  const int left = x > 0 ? p[y * w + x - 1] : (y > 0 ? p[(y - 1) * w] : 0);
  if (y == 0) return left;
  const int up = p[(y - 1) * w + x];
  if (x == 0) return up;
  return medPrediction(left, up, p[(y - 1) * w + x - 1]);
}

}  // namespace

std::vector<std::uint8_t> encodeImage(const std::string& path, const Image8& image) {
  const int w = image.width, h = image.height, c = image.channels;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  std::vector<std::uint8_t> plane(n), residual(n * c);
  const bool rct = c == 3;
  for (int ch = 0; ch < c; ++ch) {
    if (rct) {
      // Planes G, R - G, B - G (mod 256).
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint8_t* px = &image.pixels[i * 3];
        plane[i] = ch == 0 ? px[1] : static_cast<std::uint8_t>(px[ch == 1 ? 0 : 2] - px[1]);
      }
    } else {
      for (std::size_t i = 0; i < n; ++i) plane[i] = image.pixels[i * c + ch];
    }
    std::uint8_t* out = residual.data() + ch * n;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        out[i] = static_cast<std::uint8_t>(plane[i] - predict(plane.data(), w, x, y));
      }
    }
  }
  return compression::deflateRaw(path, residual.data(), residual.size(), kLevel,
                                 /*huffman_only=*/true);
}

// Plane blocks are written Huffman-only (no string matches), which cannot expand beyond 8:1; a
// block that claims far more is refused before its pixels are allocated (a 1 MB cache once took
// 1.9 GB to describe).
constexpr std::size_t kMaxPlaneRatio = 16;

Image8 decodeImage(const std::string& path, const std::string& field, const std::uint8_t* data,
                   std::size_t size, int width, int height, int channels) {
  const std::size_t n = static_cast<std::size_t>(width) * height;
  const std::vector<std::uint8_t> residual =
      compression::inflateRaw(path, field, data, size, n * channels, kMaxPlaneRatio);
  Image8 image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.resize(n * channels);
  std::vector<std::uint8_t> plane(n);
  for (int ch = 0; ch < channels; ++ch) {
    const std::uint8_t* in = residual.data() + ch * n;
    // predict() unrolled by case: the first row from the left, the first column from above, the
    // rest the MED of left, above and above-left (the same values, without the per-pixel tests).
    std::uint8_t* p = plane.data();
    int left = 0;
    for (int x = 0; x < width; ++x) left = p[x] = static_cast<std::uint8_t>(in[x] + left);
    for (int y = 1; y < height; ++y) {
      const std::uint8_t* up = p + static_cast<std::size_t>(y - 1) * width;
      std::uint8_t* row = p + static_cast<std::size_t>(y) * width;
      const std::uint8_t* r = in + static_cast<std::size_t>(y) * width;
      left = row[0] = static_cast<std::uint8_t>(r[0] + up[0]);
      for (int x = 1; x < width; ++x) {
        left = row[x] = static_cast<std::uint8_t>(r[x] + medPrediction(left, up[x], up[x - 1]));
      }
    }
    if (channels == 1) {
      std::copy(plane.begin(), plane.end(), image.pixels.begin());
    } else {
      for (std::size_t i = 0; i < n; ++i) image.pixels[i * channels + ch] = plane[i];
    }
  }
  if (channels == 3) {
    // Undo the colour transform: R = (R - G) + G, B = (B - G) + G; G is plane 0.
    for (std::size_t i = 0; i < n; ++i) {
      std::uint8_t* px = &image.pixels[i * 3];
      const std::uint8_t g = px[0];
      const std::uint8_t r = static_cast<std::uint8_t>(px[1] + g);
      const std::uint8_t b = static_cast<std::uint8_t>(px[2] + g);
      px[0] = r, px[1] = g, px[2] = b;
    }
  }
  return image;
}

std::vector<std::uint8_t> encodeRegions(const std::string& path,
                                        const std::vector<std::int32_t>& regions, int width) {
  std::vector<std::uint32_t> delta(regions.size());
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const std::uint32_t left = i % width == 0 ? 0u : static_cast<std::uint32_t>(regions[i - 1]);
    delta[i] = static_cast<std::uint32_t>(regions[i]) - left;
  }
  return compression::deflateRaw(path, reinterpret_cast<const std::uint8_t*>(delta.data()),
                                 delta.size() * 4, kLevel);
}

std::vector<std::int32_t> decodeRegions(const std::string& path, const std::string& field,
                                        const std::uint8_t* data, std::size_t size,
                                        std::size_t count, int width) {
  const std::vector<std::uint8_t> bytes =
      compression::inflateRaw(path, field, data, size, count * 4);
  std::vector<std::int32_t> regions(count);
  std::uint32_t previous = 0;
  for (std::size_t i = 0; i < count; ++i) {
    std::uint32_t d;
    std::memcpy(&d, bytes.data() + i * 4, 4);
    if (i % width == 0) previous = 0;
    previous += d;
    regions[i] = static_cast<std::int32_t>(previous);
  }
  return regions;
}

}  // namespace planes
}  // namespace io
}  // namespace sadsplat
