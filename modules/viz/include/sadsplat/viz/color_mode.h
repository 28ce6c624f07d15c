#pragma once
/// \file color_mode.h
/// \brief How a Gaussian is coloured in a view, and the per-Gaussian values behind each mode.

#include <array>
#include <cstdint>
#include <string>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace viz {

/// \brief The colourings of `sadsplat view --color`.
enum class ColorMode {
  kClass,       ///< the class colour of `label` (classes.json), grey when unlabelled
  kRgb,         ///< the view-independent colour (SH degree 0)
  kConfidence,  ///< the semantic confidence in [0, 1] (a scalar bar)
  kGate,        ///< the Hard Concrete gate's probability of being open, P(z > 0)
  kOpacity      ///< sigmoid(opacity)
};

/// \brief The mode called `name` (class, rgb, confidence, gate, opacity).
/// \throws sadsplat::Error naming the option and the modes when `name` is none of them
ColorMode parseColorMode(const std::string& name, const std::string& option = "--color");
/// \brief The name of a mode, as parseColorMode reads it.
std::string colorModeName(ColorMode mode);
/// \brief Whether a mode shows a value in [0, 1] (scalar bar) rather than colours.
bool isScalarMode(ColorMode mode);

/// \brief The value a scalar mode shows for one Gaussian, in [0, 1].
float scalarValue(const GaussianPoint& p, ColorMode mode);
/// \brief The RGB colour of the SH degree-0 coefficients (0.5 + C0 f_dc, clamped), 0..255.
std::array<std::uint8_t, 3> dcColor(const GaussianPoint& p);
/// \brief P(z > 0) of a Hard Concrete gate with sadsplat's default parameters (beta 2/3,
/// stretch (-0.1, 1.1)): sigmoid(log_alpha - beta logit(0.1 / 1.2)).
float gateOpenProbability(float log_alpha);

}  // namespace viz
}  // namespace sadsplat
