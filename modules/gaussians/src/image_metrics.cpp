#include "sadsplat/gaussians/image_metrics.h"

#include <torch/csrc/autograd/custom_function.h>

#include <cmath>

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAGuard.h>
#endif

#include "sadsplat/common/cuda_support.h"
#include "sadsplat/gaussians/step_profile.h"
#include "ssim_backend.h"

namespace sadsplat {
namespace gaussians {

namespace ssim_fused {

std::array<float, 11> window() {
  // As the reference computes it: exp(-(i - 5)^2 / (2 * 1.5^2)) in float, normalised.
  std::array<float, 11> w{};
  float sum = 0;
  for (int i = 0; i < 11; ++i) {
    w[i] = std::exp(static_cast<float>((i - 5) * (i - 5)) / (-2 * 1.5f * 1.5f));
    sum += w[i];
  }
  for (float& v : w) v /= sum;
  return w;
}

}  // namespace ssim_fused

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// mean(SSIM map) of a (differentiable) against b (a constant target), on a's device.
class FusedSsim : public torch::autograd::Function<FusedSsim> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& a, const at::Tensor& b) {
    const ScopedPhase phase("SSIM");
    const at::Tensor ac = a.contiguous(), bc = b.contiguous();
    std::array<at::Tensor, 2> out;
    if (ac.is_cuda()) {
#if SADSPLAT_HAVE_CUDA
      const c10::cuda::CUDAGuard guard(ac.device());
      out = ssim_fused::forwardCuda(ac, bc, currentStream(ac));
#endif
    } else {
      out = ssim_fused::forwardCpu(ac, bc);
    }
    ctx->save_for_backward({ac, bc, out[1]});
    return out[0].mean();
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const at::Tensor& a = saved[0];
    const ScopedPhase phase("SSIM backward");
    const at::Tensor upstream = grads[0].to(at::kFloat).contiguous();
    at::Tensor grad;
    if (a.is_cuda()) {
#if SADSPLAT_HAVE_CUDA
      const c10::cuda::CUDAGuard guard(a.device());
      grad = ssim_fused::backwardCuda(a, saved[1], saved[2], upstream, currentStream(a));
#endif
    } else {
      grad = ssim_fused::backwardCpu(a, saved[1], saved[2], upstream.item<float>());
    }
    return {grad, at::Tensor()};
  }
};

#if SADSPLAT_HAVE_CUDA
// rgbLoss on CUDA: the fused SSIM and the L1 term in one node; gradient for `a` only.
class FusedRgbLoss : public torch::autograd::Function<FusedRgbLoss> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& a, const at::Tensor& b,
                            double lambda_ssim) {
    const ScopedPhase phase("SSIM");
    const c10::cuda::CUDAGuard guard(a.device());
    const at::Tensor ac = a.contiguous(), bc = b.contiguous();
    const auto lambda = static_cast<float>(lambda_ssim);
    auto [loss, workspace] = ssim_fused::rgbLossForwardCuda(ac, bc, lambda, currentStream(ac));
    ctx->save_for_backward({ac, bc, workspace});
    ctx->saved_data["lambda_ssim"] = lambda_ssim;
    return loss;
  }
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const at::Tensor& a = saved[0];
    const auto lambda = static_cast<float>(ctx->saved_data["lambda_ssim"].toDouble());
    const ScopedPhase phase("SSIM backward");
    const c10::cuda::CUDAGuard guard(a.device());
    const at::Tensor& upstream =
        grads[0].scalar_type() == at::kFloat ? grads[0] : grads[0].to(at::kFloat);
    at::Tensor grad =
        ssim_fused::rgbLossBackwardCuda(a, saved[1], saved[2], upstream, lambda, currentStream(a));
    return {grad, at::Tensor(), at::Tensor()};
  }
};
#endif

}  // namespace

at::Tensor ssimReference(const at::Tensor& a, const at::Tensor& b) {
  const auto opts = a.options();
  at::Tensor g = at::arange(11, opts).sub(5).pow(2).div(-2 * 1.5 * 1.5).exp();
  g = g / g.sum();
  // The 11x11 Gaussian window is separable: two 1-D passes, 11x fewer operations.
  const at::Tensor rows = g.view({1, 1, 1, 11}).expand({3, 1, 1, 11}).contiguous();
  const at::Tensor cols = g.view({1, 1, 11, 1}).expand({3, 1, 11, 1}).contiguous();
  const at::Tensor x = a.permute({2, 0, 1}).unsqueeze(0), y = b.permute({2, 0, 1}).unsqueeze(0);
  auto blur = [&](const at::Tensor& t) {
    const at::Tensor h = at::conv2d(t, rows, {}, 1, at::IntArrayRef({0, 5}), 1, 3);
    return at::conv2d(h, cols, {}, 1, at::IntArrayRef({5, 0}), 1, 3);
  };
  const at::Tensor mx = blur(x), my = blur(y);
  const at::Tensor sxx = blur(x * x) - mx * mx, syy = blur(y * y) - my * my;
  const at::Tensor sxy = blur(x * y) - mx * my;
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  const at::Tensor map =
      ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2));
  return map.mean();
}

bool ssimIsFused(const at::Tensor& a, const at::Tensor& b) {
#if SADSPLAT_HAVE_CUDA
  const bool device_ok = a.device() == b.device() && (a.is_cuda() || a.is_cpu());
#else
  const bool device_ok = a.is_cpu() && b.is_cpu();
#endif
  return device_ok && a.scalar_type() == at::kFloat && b.scalar_type() == at::kFloat &&
         a.dim() == 3 && a.size(2) == 3 && a.sizes().equals(b.sizes()) && !b.requires_grad();
}

at::Tensor ssim(const at::Tensor& a, const at::Tensor& b) {
  return ssimIsFused(a, b) ? FusedSsim::apply(a, b) : ssimReference(a, b);
}

bool rgbLossIsFused(const at::Tensor& a, const at::Tensor& b) {
  return a.is_cuda() && ssimIsFused(a, b);
}

at::Tensor rgbLoss(const at::Tensor& a, const at::Tensor& b, double lambda_ssim) {
#if SADSPLAT_HAVE_CUDA
  if (rgbLossIsFused(a, b)) return FusedRgbLoss::apply(a, b, lambda_ssim);
#endif
  return (1 - lambda_ssim) * (a - b).abs().mean() + lambda_ssim * (1 - ssim(a, b));
}

double psnr(const at::Tensor& a, const at::Tensor& b) {
  const double mse = (a - b).pow(2).mean().item<double>();
  return mse > 0 ? -10.0 * std::log10(mse) : 99.0;
}

}  // namespace gaussians
}  // namespace sadsplat
