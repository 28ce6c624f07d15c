#include "sadsplat/viz/color_mode.h"

#include <algorithm>
#include <cmath>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace viz {
namespace {

float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

}  // namespace

ColorMode parseColorMode(const std::string& name, const std::string& option) {
  for (ColorMode m : {ColorMode::kClass, ColorMode::kRgb, ColorMode::kConfidence, ColorMode::kGate,
                      ColorMode::kOpacity}) {
    if (colorModeName(m) == name) return m;
  }
  throw Error("<command line>", option, "one of class, rgb, confidence, gate, opacity", name);
}

std::string colorModeName(ColorMode mode) {
  switch (mode) {
    case ColorMode::kClass:
      return "class";
    case ColorMode::kRgb:
      return "rgb";
    case ColorMode::kConfidence:
      return "confidence";
    case ColorMode::kGate:
      return "gate";
    case ColorMode::kOpacity:
      return "opacity";
  }
  return "class";
}

bool isScalarMode(ColorMode mode) {
  return mode == ColorMode::kConfidence || mode == ColorMode::kGate || mode == ColorMode::kOpacity;
}

float gateOpenProbability(float log_alpha) {
  // Louizos et al.'s closed form with the stretch (l, r) = (-0.1, 1.1), beta = 2/3
  // (hard_concrete.h).
  const float beta = 2.0f / 3.0f;
  const float t = 0.1f / 1.2f;
  return sigmoid(log_alpha - beta * std::log(t / (1.0f - t)));
}

float scalarValue(const GaussianPoint& p, ColorMode mode) {
  switch (mode) {
    case ColorMode::kConfidence:
      return std::clamp(p.confidence, 0.0f, 1.0f);
    case ColorMode::kGate:
      return gateOpenProbability(p.log_alpha);
    case ColorMode::kOpacity:
      return sigmoid(p.opacity);
    default:
      return 0.0f;
  }
}

std::array<std::uint8_t, 3> dcColor(const GaussianPoint& p) {
  constexpr float kC0 = 0.28209479177387814f;  // SH degree-0 basis constant
  std::array<std::uint8_t, 3> rgb{};
  for (int c = 0; c < 3; ++c) {
    const float v = std::clamp(0.5f + kC0 * p.f_dc[c], 0.0f, 1.0f);
    rgb[c] = static_cast<std::uint8_t>(std::lround(255.0f * v));
  }
  return rgb;
}

}  // namespace viz
}  // namespace sadsplat
