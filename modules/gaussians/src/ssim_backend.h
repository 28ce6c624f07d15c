#pragma once
// Internal interface of the fused SSIM (image_metrics.cpp <-> ssim_cpu.cpp, ssim_cuda.cu): the
// loss's SSIM of two [H, W, 3] float32 images in four memory-bound passes instead of ten
// convolutions and ~30 element-wise kernels. Same definition as the reference composition in
// image_metrics.cpp: 11x11 Gaussian window (sigma 1.5), zero padding, C1 = 0.01^2, C2 = 0.03^2,
// mean over H x W x 3. The gradient is taken with respect to the first image only (the second is
// the target).

#include <ATen/ATen.h>

#include <array>

namespace sadsplat {
namespace gaussians {
namespace ssim_fused {

/// The normalised 1-D window, as the reference computes it (float).
std::array<float, 11> window();

/// forwardCuda / backwardCuda on the CPU: contiguous float32 [H, W, 3] CPU tensors; `upstream`
/// the incoming gradient of the mean as a number.
std::array<at::Tensor, 2> forwardCpu(const at::Tensor& a, const at::Tensor& b);
at::Tensor backwardCpu(const at::Tensor& a, const at::Tensor& b, const at::Tensor& partials,
                       float upstream);

#if SADSPLAT_COMPILE_CUDA
/// SSIM map [H, W, 3] and the per-pixel partial derivatives of the map with respect to the
/// blurred statistics of `a` (mean, E[a^2], E[ab]) stacked as [3, H, W, 3] (for the backward).
/// a, b: contiguous float32 [H, W, 3] on the current CUDA device; stream a cudaStream_t.
std::array<at::Tensor, 2> forwardCuda(const at::Tensor& a, const at::Tensor& b, void* stream);
/// d(upstream * mean of the map)/da, [H, W, 3], from forwardCuda's partials; `upstream` a float32
/// scalar tensor on the device.
at::Tensor backwardCuda(const at::Tensor& a, const at::Tensor& b, const at::Tensor& partials,
                        const at::Tensor& upstream, void* stream);
/// The training's RGB loss (1 - lambda) mean|a - b| + lambda (1 - mean SSIM(a, b)) as a float32
/// scalar on the device (the means summed in a fixed order: no atomics), and the workspace that
/// rgbLossBackwardCuda takes (it holds forwardCuda's partials). Two allocations and three kernels.
std::array<at::Tensor, 2> rgbLossForwardCuda(const at::Tensor& a, const at::Tensor& b, float lambda,
                                             void* stream);
/// d(upstream * loss)/da, [H, W, 3]; reuses part of `workspace` as scratch (the partials stay).
at::Tensor rgbLossBackwardCuda(const at::Tensor& a, const at::Tensor& b,
                               const at::Tensor& workspace, const at::Tensor& upstream,
                               float lambda, void* stream);
#endif

}  // namespace ssim_fused
}  // namespace gaussians
}  // namespace sadsplat
