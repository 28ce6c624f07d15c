#pragma once
/// \file surface_layer.h
/// \brief The first surface along each ray of a render: where the transmittance of the
/// Gaussians, composited front to back as the rasterizer composites them, falls below a level
/// (0.5: the median depth of 2DGS / RaDe-GS). The class and the height a map should show are
/// those of that surface, not the blend through it that RenderResult::depth and ::features give
/// (a floater or a roof's edge above the ground pulls the expected depth half-way between); the
/// surface check of the cloud's Gaussians (surfaceGapSums) compares with it too.

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
  /// its standard deviations in z of its centre); 0 where not reached. Orthographic: the
  /// conditional mean of z given the pixel's x, y (with the rasterizer's dilation); pinhole: the
  /// maximum along the ray through the pixel.
  at::Tensor depth;
  /// [H, W, C] float: the features of the Gaussians composited up to and including that one
  /// (everything composited where not reached), divided by the sum of their blend weights.
  at::Tensor features;
  /// [H, W] float: that sum of blend weights (1 - the transmittance where compositing stopped).
  at::Tensor weight;
};

/// \brief Composites the Gaussians through `camera` (orthographic or pinhole) in the
/// rasterizer's order (centre depth, then index) and with its alpha (raster_math.h's pixelAlpha,
/// the rasterizer's early stop at kMinTransmittance) until the transmittance falls below
/// `level`. Forward only, on the CPU in double (the Gaussians may live on any device; the result
/// is on the CPU).
/// \throws sadsplat::Error for a level outside (1e-4, 1), an empty camera, or shapes the
/// rasterizer would refuse
SurfaceLayer renderSurfaceLayer(const GaussianParams& gaussians, const RasterCamera& camera,
                                double level = 0.5);

/// \brief Per Gaussian, where it is seen in `camera`, how far the surface lies behind it: over
/// the pixels whose transmittance falls below `level` (renderSurfaceLayer's surface, depth D)
/// and where the Gaussian is composited before or as it falls (in front of the surface or its
/// part, not hidden behind it), the sums of its blend weights w and of w (D - z), z its centre's
/// camera z. A Gaussian hidden behind the surface, or drawn only where no surface is reached,
/// sums to 0 there. Σ w (D - z) / Σ w is the gap between the Gaussian and the surface it shows
/// (positive: the surface lies behind it, a floater's sign). (Its own surface on each ray in
/// place of its centre lets an opaque floater pass: it makes the surface it is compared with.)
/// \return [N, 2] double on the CPU: (Σ w, Σ w (D - z))
/// \throws sadsplat::Error as renderSurfaceLayer
at::Tensor surfaceGapSums(const GaussianParams& gaussians, const RasterCamera& camera,
                          double level = 0.5);

}  // namespace gaussians
}  // namespace sadsplat
