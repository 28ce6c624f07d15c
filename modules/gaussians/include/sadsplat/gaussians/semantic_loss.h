#pragma once
// The semantic loss of the paper ("Training Loss") on a rendered feature image.

#include <ATen/ATen.h>

namespace sadsplat {
namespace gaussians {

/// \brief The semantic loss of the paper ("Training Loss"): 1 - cosine similarity between the
/// decoded feature (linear layer W, b) and the one-hot embedding of the pixel's class, averaged
/// over supervised pixels only (labels >= 0); pixels with label -1 contribute neither value nor
/// gradient. On CUDA (float32, D <= 32 feature channels, C <= 16 classes) the value and the
/// gradients come from fused kernels (semanticLossIsFused); otherwise as semanticLossReference.
/// \param[in] features [H, W, D] rendered feature image
/// \param[in] labels [H, W] int64 class ids in [0, C) or -1 = not supervised
/// \param[in] weight [C, D] decoder weight; \param[in] bias [C] decoder bias. Gradients flow to
/// each of features, weight and bias that requires them.
at::Tensor semanticLoss(const at::Tensor& features, const at::Tensor& labels,
                        const at::Tensor& weight, const at::Tensor& bias);

/// \brief The same loss as a composition of ATen operations (any device and floating type): the
/// reference the fused path is tested against.
at::Tensor semanticLossReference(const at::Tensor& features, const at::Tensor& labels,
                                 const at::Tensor& weight, const at::Tensor& bias);

/// \brief Whether semanticLoss(features, labels, weight, bias) takes the fused path.
bool semanticLossIsFused(const at::Tensor& features, const at::Tensor& labels,
                         const at::Tensor& weight, const at::Tensor& bias);

}  // namespace gaussians
}  // namespace sadsplat
