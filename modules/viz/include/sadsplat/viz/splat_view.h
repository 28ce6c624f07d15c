#pragma once
/// \file splat_view.h
/// \brief A VTK view of semantic Gaussian clouds, coloured by class, colour, confidence, gate or
/// opacity; one model, or two side by side with linked cameras; an interactive window or a PNG
/// screenshot. Two modes: "splat" (default) shows the image sadsplat's rasterizer renders for the
/// VTK camera (ViewModel::frames), as the model really looks, classes decoded per pixel for a
/// run; re-rendered at a quarter of the resolution while the camera moves and in full when it
/// stops. "points" draws each Gaussian as an opaque disc (vtkPointGaussianMapper) over its
/// footprint (where opacity x exp(-d^2 / 2 sigma^2) >= 1/4), to inspect single Gaussians.

#include <array>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "sadsplat/viz/color_mode.h"
#include "sadsplat/viz/view_model.h"

namespace sadsplat {
namespace viz {

/// \brief How to show the models.
struct SplatViewOptions {
  /// "splat" (the rasterizer's image) or "points" (discs).
  std::string mode = "splat";
  ColorMode color = ColorMode::kClass;
  /// Classes to show (names from the class list, or ids); empty: all.
  std::vector<std::string> classes;
  /// A camera of the run's scene to start from (e.g. "view_042"); empty: an aerial view from
  /// 45 degrees above the ground, facing the centre of the bulk of the Gaussians.
  std::string view;
  int width = 1280;
  int height = 720;
  /// PNG to write (offscreen render, then return); empty: an interactive window.
  std::string screenshot;
  /// Factor on every splat's radius.
  double splat_scale = 1.0;
  /// Background colour, 0..255.
  std::array<std::uint8_t, 3> background{28, 30, 36};
};

/// \brief The key list of the interactive window (printed at its start).
std::string keyHelp();

/// \brief Shows one model, or several side by side with one camera, as `options` say.
/// \param[in] models one or two models (the second: `--compare`)
/// \param[in] options colouring, classes, camera, size, screenshot
/// \param[in] log where the key list and screenshot paths are printed (may be null)
/// \throws sadsplat::Error on an unknown class or view, a colouring the model cannot show (no
/// semantic fields), no X display, or a screenshot that cannot be written
void showModels(const std::vector<ViewModel>& models, const SplatViewOptions& options,
                std::ostream* log);

}  // namespace viz
}  // namespace sadsplat
