#pragma once
// Internal interface of the fused semantic loss (semantic_loss.cpp <-> semantic_loss_cuda.cu).
// Per supervised pixel p with feature f (D channels), logits l = W f + b (C classes), target t:
//   loss_p = 1 - l_t / max(|l|, 1e-8),  loss = sum_p loss_p / max(#supervised, 1).
// The forward pass reduces the sum and the count on the device; the backward pass recomputes the
// logits (cheaper than storing them), writes d loss / d f and sums the decoder's gradients.

#include <ATen/ATen.h>

#include <array>

namespace sadsplat {
namespace gaussians {
namespace semantic_loss_fused {

/// Largest feature and class counts of the fused kernels (the paper's 32 channels; a lane holds
/// one channel and 16 logits; an instantiation for 64 x 64 was slower than the reference on an
/// H100 and was dropped).
constexpr int kMaxChannels = 32;
constexpr int kMaxClasses = 16;

#if SADSPLAT_COMPILE_CUDA
/// {[2] float64: the sum of the supervised pixels' losses and their count; the loss, a float32
/// scalar} on the device. features [H, W, D] float32 with unit channel stride and one pixel
/// stride (stride(0) = W stride(1): a slice of the rasterizer's image is read in place), labels
/// [H, W] contiguous int64, weight [C, D] and bias [C] contiguous float32, all on the current
/// CUDA device; stream a cudaStream_t.
std::array<at::Tensor, 2> forwardCuda(const at::Tensor& features, const at::Tensor& labels,
                                      const at::Tensor& weight, const at::Tensor& bias,
                                      void* stream);
/// {d(upstream * loss)/d features [H, W, D] (contiguous), .../d weight [C, D], .../d bias [C]}
/// given forwardCuda's sums; `upstream` a float32 scalar tensor on the device (no host
/// synchronisation). The decoder's gradients are undefined unless `decoder`.
std::array<at::Tensor, 3> backwardCuda(const at::Tensor& features, const at::Tensor& labels,
                                       const at::Tensor& weight, const at::Tensor& bias,
                                       const at::Tensor& sums, const at::Tensor& upstream,
                                       bool decoder, void* stream);
#endif

}  // namespace semantic_loss_fused
}  // namespace gaussians
}  // namespace sadsplat
