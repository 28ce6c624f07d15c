#include "sadsplat/gaussians/semantic_loss.h"

#include <torch/csrc/autograd/custom_function.h>

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAGuard.h>
#endif

#include "sadsplat/common/cuda_support.h"
#include "sadsplat/gaussians/step_profile.h"
#include "semantic_loss_backend.h"

namespace sadsplat {
namespace gaussians {

namespace {

#if SADSPLAT_HAVE_CUDA
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// The loss of features [H, W, D] against labels [H, W]; gradients for features, weight, bias.
class FusedSemanticLoss : public torch::autograd::Function<FusedSemanticLoss> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& features,
                            const at::Tensor& labels, const at::Tensor& weight,
                            const at::Tensor& bias) {
    const ScopedPhase phase("semantic loss");
    const c10::cuda::CUDAGuard guard(features.device());
    // The rasterizer's feature image is a slice of its [H, W, 3 + D] output: read in place when
    // the pixels can be addressed with one stride.
    const bool one_stride =
        features.stride(2) == 1 && features.stride(0) == features.size(1) * features.stride(1);
    const at::Tensor f = one_stride ? features : features.contiguous();
    const at::Tensor l = labels.is_contiguous() ? labels : labels.contiguous();
    const at::Tensor w = weight.contiguous(), b = bias.contiguous();
    auto [sums, loss] = semantic_loss_fused::forwardCuda(f, l, w, b, currentStream(f));
    ctx->save_for_backward({f, l, w, b, sums});
    return loss;
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const at::Tensor &f = saved[0], &w = saved[2];
    const ScopedPhase phase("semantic loss backward");
    const c10::cuda::CUDAGuard guard(f.device());
    const at::Tensor& upstream =
        grads[0].scalar_type() == at::kFloat ? grads[0] : grads[0].to(at::kFloat);
    const bool decoder = ctx->needs_input_grad(2) || ctx->needs_input_grad(3);
    auto [grad_f, grad_w, grad_b] = semantic_loss_fused::backwardCuda(
        f, saved[1], w, saved[3], saved[4], upstream, decoder, currentStream(f));
    return {grad_f, at::Tensor(), grad_w, grad_b};
  }
};
#endif

}  // namespace

at::Tensor semanticLossReference(const at::Tensor& features, const at::Tensor& labels,
                                 const at::Tensor& weight, const at::Tensor& bias) {
  const at::Tensor supervised = labels >= 0;
  const at::Tensor logits = at::linear(features, weight, bias);
  const at::Tensor target = labels.clamp_min(0).unsqueeze(2);
  const at::Tensor cosine = logits.gather(2, target).squeeze(2) / logits.norm(2, 2).clamp_min(1e-8);
  // where() (not a multiplication by the mask) so unsupervised pixels get exactly zero gradient.
  const at::Tensor per_pixel = at::where(supervised, 1 - cosine, at::zeros_like(cosine));
  return per_pixel.sum() / supervised.sum().clamp_min(1).to(per_pixel.scalar_type());
}

bool semanticLossIsFused(const at::Tensor& features, const at::Tensor& labels,
                         const at::Tensor& weight, const at::Tensor& bias) {
#if SADSPLAT_HAVE_CUDA
  const auto device = features.device();
  return features.is_cuda() && features.scalar_type() == at::kFloat && features.dim() == 3 &&
         features.size(2) >= 1 && features.size(2) <= semantic_loss_fused::kMaxChannels &&
         labels.device() == device && labels.scalar_type() == at::kLong && labels.dim() == 2 &&
         labels.size(0) == features.size(0) && labels.size(1) == features.size(1) &&
         weight.device() == device && weight.scalar_type() == at::kFloat && weight.dim() == 2 &&
         weight.size(1) == features.size(2) && weight.size(0) >= 1 &&
         weight.size(0) <= semantic_loss_fused::kMaxClasses && bias.device() == device &&
         bias.scalar_type() == at::kFloat && bias.dim() == 1 && bias.size(0) == weight.size(0) &&
         !labels.requires_grad();
#else
  (void)features;
  (void)labels;
  (void)weight;
  (void)bias;
  return false;
#endif
}

at::Tensor semanticLoss(const at::Tensor& features, const at::Tensor& labels,
                        const at::Tensor& weight, const at::Tensor& bias) {
#if SADSPLAT_HAVE_CUDA
  if (semanticLossIsFused(features, labels, weight, bias))
    return FusedSemanticLoss::apply(features, labels, weight, bias);
#endif
  return semanticLossReference(features, labels, weight, bias);
}

}  // namespace gaussians
}  // namespace sadsplat
