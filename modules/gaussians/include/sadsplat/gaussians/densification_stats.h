#pragma once
/// \file densification_stats.h
/// \brief The densification statistics of one render (3DGS): for every Gaussian the render saw
/// (radius > 0), the length of its screen-space position gradient in NDC units is added to
/// `grad_accum`, 1 to `denom`, and `max_radii` keeps its largest radius. On CUDA (float32) one
/// kernel updates the three in place; elsewhere the same arithmetic as ATen operations.

#include <ATen/ATen.h>

namespace sadsplat {
namespace gaussians {

/// \brief Adds one render's statistics in place.
/// \param[in] means2d_grad [N, 2] gradient of the loss by the 2D means (pixels)
/// \param[in] radii [N] int32 screen radii of the render (0: not seen)
/// \param[in] scale_x, scale_y factors from pixels to NDC units (and the batch size)
/// \param[in,out] grad_accum, denom, max_radii [N] float32, on the gradient's device
void accumulateScreenGradients(const at::Tensor& means2d_grad, const at::Tensor& radii,
                               double scale_x, double scale_y, at::Tensor& grad_accum,
                               at::Tensor& denom, at::Tensor& max_radii);

/// \brief The same as ATen operations on any device (the reference the kernel is tested against).
void accumulateScreenGradientsReference(const at::Tensor& means2d_grad, const at::Tensor& radii,
                                        double scale_x, double scale_y, at::Tensor& grad_accum,
                                        at::Tensor& denom, at::Tensor& max_radii);

}  // namespace gaussians
}  // namespace sadsplat
