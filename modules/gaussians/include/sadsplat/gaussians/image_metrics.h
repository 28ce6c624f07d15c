#pragma once
/// \file image_metrics.h
/// \brief Image similarity used as loss and metric: SSIM (11x11 Gaussian window, sigma 1.5, as in
/// 3DGS) and PSNR, on [H, W, 3] images with values in [0, 1]. Differentiable.

#include <ATen/ATen.h>

namespace sadsplat {
namespace gaussians {

/// \brief Mean SSIM of two [H, W, 3] images. On float32 images (CPU or CUDA) whose second image
/// needs no gradient (a loss against a target) it runs fused (four memory-bound passes, the
/// gradient for the first image only); otherwise as ssimReference.
at::Tensor ssim(const at::Tensor& a, const at::Tensor& b);
/// \brief The same SSIM composed of ATen operations (separable convolutions), on any device and
/// differentiable in both images: the reference the fused path is tested against.
at::Tensor ssimReference(const at::Tensor& a, const at::Tensor& b);
/// \brief Whether ssim(a, b) takes the fused path.
bool ssimIsFused(const at::Tensor& a, const at::Tensor& b);
/// \brief The training's RGB loss of a render `a` against its target `b` (3DGS):
/// (1 - lambda_ssim) mean|a - b| + lambda_ssim (1 - ssim(a, b)). On CUDA, where ssim is fused, it
/// is one autograd node (the L1 term's gradient added in the SSIM's backward: ~7 fewer nodes and
/// their operator calls per render for the host to issue); elsewhere the composition of ATen
/// operations and ssim (whose bits the CPU trainings keep). The same values up to rounding.
at::Tensor rgbLoss(const at::Tensor& a, const at::Tensor& b, double lambda_ssim);
/// \brief Whether rgbLoss(a, b, ...) is the one fused node.
bool rgbLossIsFused(const at::Tensor& a, const at::Tensor& b);
/// \brief PSNR in dB of two images with values in [0, 1].
double psnr(const at::Tensor& a, const at::Tensor& b);

}  // namespace gaussians
}  // namespace sadsplat
