#pragma once
/// \file splat_frame.h
/// \brief One rendered image of a Gaussian model, as a viewer shows it: the rasterizer's
/// accumulated opacity and, depending on what was asked, its colour, its decoded classes or a
/// per-Gaussian value blended like a colour. Plain data, so that the VTK viewer (no LibTorch)
/// and the renderer (no VTK) share it.

#include <cstdint>
#include <functional>
#include <vector>

#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {

/// \brief What a frame shows.
enum class FrameContent {
  kRgb,      ///< the model's colour (spherical harmonics, view-dependent)
  kClasses,  ///< per-pixel class ids (the model's decoder, or its Gaussians' labels blended)
  kScalar    ///< a per-Gaussian value in [0, 1] blended like a colour
};

/// \brief A rendered frame, row-major, width x height pixels.
struct SplatFrame {
  int width = 0;
  int height = 0;
  std::vector<float> alpha;           ///< accumulated opacity in [0, 1]
  std::vector<std::uint8_t> rgb;      ///< kRgb: 3 bytes a pixel, composited over black
  std::vector<std::int16_t> classes;  ///< kClasses: class id, -1 where alpha < 0.5
  std::vector<float> scalar;          ///< kScalar: the blended value / alpha, 0 where alpha is 0
};

/// \brief What to render: the camera, the content, the per-Gaussian value of kScalar (given a
/// Gaussian's point, in [0, 1]) and which class labels are drawn.
struct FrameRequest {
  PinholeCamera camera;
  FrameContent content = FrameContent::kRgb;
  std::function<float(const GaussianPoint&)> scalar;
  std::function<bool(std::uint32_t label)> visible;  ///< null: every Gaussian
};

/// \brief Something that renders frames of one model (the viewer's splat mode).
using FrameSource = std::function<SplatFrame(const FrameRequest&)>;

}  // namespace io
}  // namespace sadsplat
