#pragma once
/// \file surface_layer.h
/// \brief The first surface along each ray of a top-down map render: where the transmittance of
/// the Gaussians, composited front to back as the rasterizer composites them, falls below a
/// level (0.5: the median depth of 2DGS / RaDe-GS). The class and the height a map should show
/// are those of that surface, not the blend through it that RenderResult::depth and ::features
/// give (a floater or a roof's edge above the ground pulls the expected depth half-way between).

#include <ATen/ATen.h>

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace gaussians {

/// \brief Per pixel: the surface where the transmittance falls below the level, and the
/// features of the Gaussians in front of it.
struct SurfaceLayer {
  /// [H, W] bool: the transmittance fell below the level (the pixel shows a surface).
  at::Tensor reached;
  /// [H, W] float: camera z of the surface: on the ray, the point of the Gaussian whose alpha
  /// took the transmittance below the level (its density's maximum along the ray, within 3 of
  /// its standard deviations in z of its centre); 0 where not reached.
  at::Tensor depth;
  /// [H, W, C] float: the features of the Gaussians composited up to and including that one
  /// (everything composited where not reached), divided by the sum of their blend weights.
  at::Tensor features;
  /// [H, W] float: that sum of blend weights (1 - the transmittance where compositing stopped).
  at::Tensor weight;
};

/// \brief Composites the Gaussians through an orthographic `camera` in the rasterizer's order
/// (centre depth, then index) and with its alpha (raster_math.h's pixelAlpha, the rasterizer's
/// early stop at kMinTransmittance) until the transmittance falls below `level`. Forward only,
/// on the CPU in double (the Gaussians may live on any device; the result is on the CPU).
/// \throws sadsplat::Error for a pinhole camera, a level outside (1e-4, 1), or shapes the
/// rasterizer would refuse
SurfaceLayer renderSurfaceLayer(const GaussianParams& gaussians, const RasterCamera& camera,
                                double level = 0.5);

}  // namespace gaussians
}  // namespace sadsplat
