#pragma once
// Small conversions shared by the web splat codecs (.splat, .spz, SOG, compressed PLY): 8-bit
// quantisation, the opacity sigmoid and its inverse, quaternions.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace io {
namespace splat_codec {

constexpr float kC0 = 0.28209479177387814f;  // SH degree-0 basis constant

inline std::uint8_t toByte(float v) {
  return static_cast<std::uint8_t>(std::clamp(std::round(v), 0.0f, 255.0f));
}

inline float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

// The opacity logit of an alpha in [0, 1], kept finite: alpha is clamped to half a step of 8 bits
// from 0 and 1 (what 3DGS decoders turn into an infinite logit).
inline float logitOfAlpha(float alpha) {
  const float p = std::clamp(alpha, 0.5f / 255.0f, 254.5f / 255.0f);
  return std::log(p / (1.0f - p));
}

// The normalised quaternion (w, x, y, z) of a point, identity when it is zero.
inline std::array<float, 4> unitQuaternion(const GaussianPoint& p) {
  const float n = std::sqrt(p.rot[0] * p.rot[0] + p.rot[1] * p.rot[1] + p.rot[2] * p.rot[2] +
                            p.rot[3] * p.rot[3]);
  if (!(n > 0)) return {1, 0, 0, 0};
  return {p.rot[0] / n, p.rot[1] / n, p.rot[2] / n, p.rot[3] / n};
}

inline void finishCloud(pcl::PointCloud<GaussianPoint>& cloud) {
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
}

}  // namespace splat_codec
}  // namespace io
}  // namespace sadsplat
