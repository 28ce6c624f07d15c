#pragma once
/// \file image_metrics.h
/// \brief Image similarity used as loss and metric: SSIM (11x11 Gaussian window, sigma 1.5, as in
/// 3DGS) and PSNR, on [H, W, 3] images with values in [0, 1]. Differentiable.

#include <ATen/ATen.h>

namespace sadsplat {
namespace gaussians {

/// \brief Mean SSIM of two [H, W, 3] images.
at::Tensor ssim(const at::Tensor& a, const at::Tensor& b);
/// \brief PSNR in dB of two images with values in [0, 1].
double psnr(const at::Tensor& a, const at::Tensor& b);

}  // namespace gaussians
}  // namespace sadsplat
