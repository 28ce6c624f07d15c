#pragma once
/// \file rasterizer.h
/// \brief The differentiable Gaussian rasterizer: RGB (spherical harmonics) + an N-channel
/// feature image + alpha + expected depth in one pass, on CPU or CUDA tensors.
///
/// The method is that of 3D Gaussian Splatting: EWA projection with a 0.3 px low-pass dilation,
/// 16x16 tile binning, per-tile depth sort, front-to-back compositing with early termination,
/// and a back-to-front backward pass. Every output is differentiable (autograd) with respect to
/// every input. The CPU backend is the reference; the CUDA backend gives the same results.

#include <ATen/ATen.h>

#include <array>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace gaussians {

class TileListCapacity;

/// \brief A pinhole or orthographic camera for rendering (COLMAP conventions, see
/// io::PinholeCamera). Orthographic: pixel = (fx x_cam + cx, fy y_cam + cy), fx and fy in pixels
/// per world unit, depth = z_cam; every ray runs along the camera's z axis (a top-down map render).
struct RasterCamera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 4> qvec{1, 0, 0, 0};  ///< world-to-camera rotation (w, x, y, z)
  std::array<double, 3> tvec{0, 0, 0};     ///< world-to-camera translation
  double near_plane = 0.01;                ///< Gaussians closer than this are culled
  bool orthographic = false;               ///< affine projection (see above)

  /// \brief The camera of an imported view.
  static RasterCamera fromPinhole(const io::PinholeCamera& camera);
  /// \brief Camera centre in world coordinates (-R^T t).
  std::array<double, 3> centre() const;
  /// \brief Where the spherical harmonics are seen from: the centre (pinhole), or a point far back
  /// along the viewing axis (orthographic: one view direction for every Gaussian).
  std::array<double, 3> shViewpoint() const;
  /// \brief Sets qvec from a row-major world-to-camera rotation matrix.
  void setRotation(const std::array<double, 9>& R);
};

/// \brief What to render.
struct RenderSettings {
  int sh_degree = 3;                         ///< 0..3; sh must hold (degree+1)^2 coefficients
  std::array<float, 3> background{0, 0, 0};  ///< RGB behind the Gaussians
  /// Render the semantic features (false: RenderResult::features has 0 channels and the
  /// rasterizer blends 32 fewer channels; the features get no gradient from this render).
  bool features = true;
  /// Render the expected depth (false: RenderResult::depth is undefined; one channel fewer).
  bool depth = true;
  /// CUDA: size the (Gaussian, tile) list from earlier renders instead of waiting for the GPU
  /// to count it; the caller checks with tile_capacity->renderedAll() before using the render's
  /// gradients (tile_list_capacity.h). Null: exact lists. Kept alive by the caller. CPU: unused.
  TileListCapacity* tile_capacity = nullptr;
  /// Gradients for closed gates (not the paper; MaskGaussian's masked rasterisation): a Gaussian
  /// whose opacity_gate is exactly 0 still renders nothing, but its gate gets the derivative of
  /// the render at gate 0 — the pixels it would reach if open, behind and in front of the others
  /// as the list orders them — instead of none. Costs its (Gaussian, tile) pairs in the lists.
  bool closed_gate_gradients = false;
};

/// \brief The Gaussians to render: N rows, float32 (or float64 on CPU), one device.
struct GaussianParams {
  at::Tensor means;           ///< [N, 3]
  at::Tensor quats;           ///< [N, 4] (w, x, y, z), need not be normalised
  at::Tensor log_scales;      ///< [N, 3]
  at::Tensor opacity_logits;  ///< [N]
  at::Tensor sh;              ///< [N, K, 3], K >= (sh_degree + 1)^2; with sh_rest: [N, 1, 3]
  /// Optional: the SH coefficients after the first, [N, K - 1, 3], with `sh` holding only the
  /// first (how the trainer stores them; both are read in place, no [N, K, 3] copy per render).
  at::Tensor sh_rest;
  at::Tensor features;        ///< [N, C] semantic features, C = 0..64+ (may be undefined: C = 0)
  at::Tensor opacity_gate;    ///< [N] optional factor on the activated opacity (Hard Concrete gate)
};

/// \brief Rendered images and the per-Gaussian data densification needs.
struct RenderResult {
  at::Tensor rgb;       ///< [H, W, 3] colour composited over the background
  at::Tensor features;  ///< [H, W, C]
  at::Tensor alpha;     ///< [H, W] accumulated opacity
  at::Tensor depth;     ///< [H, W] expected depth (alpha-weighted mean camera z), 0 where alpha = 0
                        ///< (undefined when RenderSettings::depth is false)
  at::Tensor means2d;   ///< [N, 2] projected centres (pixels); call retain_grad() before backward
                        ///< to read the screen-space gradient
  at::Tensor radii;     ///< [N] int32 screen radius, 0 = culled
};

/// \brief Renders the Gaussians through a camera.
/// \throws sadsplat::Error on inconsistent shapes, dtypes or devices, or a CUDA tensor in a build
/// without CUDA
RenderResult render(const GaussianParams& gaussians, const RasterCamera& camera,
                    const RenderSettings& settings = {});

/// \brief Colour of each Gaussian seen from `camera_centre`: SH of degree `degree` evaluated in
/// the view direction, + 0.5, clamped at 0 (as in 3DGS). Differentiable. Returns [N, 3].
at::Tensor evaluateSh(const at::Tensor& sh, const at::Tensor& means,
                      const std::array<double, 3>& camera_centre, int degree);
/// \brief The same with the coefficients in two parts: the first [N, 1, 3] and the others
/// [N, K - 1, 3] (GaussianParams::sh and sh_rest); each part gets its own gradient.
at::Tensor evaluateSh(const at::Tensor& sh_dc, const at::Tensor& sh_rest, const at::Tensor& means,
                      const std::array<double, 3>& camera_centre, int degree);

/// \brief Projection step alone (differentiable): returns {means2d [N,2], conics [N,3],
/// depths [N], radii [N] int32}.
std::array<at::Tensor, 4> projectGaussians(const at::Tensor& means, const at::Tensor& quats,
                                           const at::Tensor& log_scales,
                                           const RasterCamera& camera);

/// \brief Compositing step alone (differentiable in means2d, conics, opacities, values):
/// returns {image [H,W,D] without background, alpha [H,W]}.
std::array<at::Tensor, 2> rasterizeToPixels(const at::Tensor& means2d, const at::Tensor& conics,
                                            const at::Tensor& opacities, const at::Tensor& values,
                                            const at::Tensor& radii, const at::Tensor& depths,
                                            int width, int height);

}  // namespace gaussians
}  // namespace sadsplat
