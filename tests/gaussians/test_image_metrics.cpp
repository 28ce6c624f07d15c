// SSIM and PSNR: known values, gradients against finite differences, and the fused CUDA SSIM
// against the reference composition (where LibTorch has a CUDA device).
#include <gtest/gtest.h>

#include <ATen/Context.h>
#include <torch/csrc/autograd/autograd.h>

#include <cmath>

#include "sadsplat/gaussians/image_metrics.h"

namespace sadsplat {
namespace {

using gaussians::ssim;
using gaussians::ssimReference;

at::Tensor randomImage(int H, int W, std::uint64_t seed, at::ScalarType type = at::kFloat) {
  at::manual_seed(seed);
  return at::rand({H, W, 3}, at::TensorOptions().dtype(type));
}

// SSIM by its definition, in double, one pixel and channel at a time: the 11x11 Gaussian window
// (sigma 1.5) over the zero-padded images, C1 = 0.01^2, C2 = 0.03^2, mean of the map.
double directSsim(const at::Tensor& a_in, const at::Tensor& b_in) {
  const at::Tensor a = a_in.detach().cpu().to(at::kDouble).contiguous();
  const at::Tensor b = b_in.detach().cpu().to(at::kDouble).contiguous();
  const int H = static_cast<int>(a.size(0)), W = static_cast<int>(a.size(1));
  const auto A = a.accessor<double, 3>(), B = b.accessor<double, 3>();
  double g[11], sum = 0;
  for (int i = 0; i < 11; ++i) sum += g[i] = std::exp(-(i - 5) * (i - 5) / (2 * 1.5 * 1.5));
  double total = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) {
        double s[5] = {0, 0, 0, 0, 0};
        for (int dy = -5; dy <= 5; ++dy) {
          for (int dx = -5; dx <= 5; ++dx) {
            const int yy = y + dy, xx = x + dx;
            if (yy < 0 || yy >= H || xx < 0 || xx >= W) continue;
            const double w = g[dy + 5] * g[dx + 5] / (sum * sum);
            const double p = A[yy][xx][c], q = B[yy][xx][c];
            s[0] += w * p;
            s[1] += w * q;
            s[2] += w * p * p;
            s[3] += w * q * q;
            s[4] += w * p * q;
          }
        }
        const double sxx = s[2] - s[0] * s[0], syy = s[3] - s[1] * s[1], sxy = s[4] - s[0] * s[1];
        total += ((2 * s[0] * s[1] + 1e-4) * (2 * sxy + 9e-4)) /
                 ((s[0] * s[0] + s[1] * s[1] + 1e-4) * (sxx + syy + 9e-4));
      }
    }
  }
  return total / (3.0 * H * W);
}

TEST(ImageMetrics, SsimIsItsDefinition) {
  for (const auto& [H, W] : {std::pair<int, int>{9, 13}, {4, 6}, {30, 20}}) {
    const at::Tensor a = randomImage(H, W, 8);
    const at::Tensor b = (a * 0.6 + randomImage(H, W, 9) * 0.4).contiguous();
    EXPECT_NEAR(ssimReference(a, b).item<double>(), directSsim(a, b), 1e-5) << H << "x" << W;
  }
}

TEST(ImageMetrics, SsimOfAnImageWithItselfIsOneAndPsnrOfADifferenceIsKnown) {
  const at::Tensor a = randomImage(20, 30, 1);
  EXPECT_NEAR(ssim(a, a).item<double>(), 1.0, 1e-5);
  EXPECT_LT(ssim(a, randomImage(20, 30, 2)).item<double>(), 0.2);
  // A constant difference of 0.1: MSE 0.01, PSNR 20 dB.
  EXPECT_NEAR(gaussians::psnr(a, a + 0.1), 20.0, 1e-4);
  EXPECT_EQ(gaussians::psnr(a, a), 99.0);
}

TEST(ImageMetrics, SsimGradientMatchesFiniteDifferences) {
  const at::Tensor a = randomImage(12, 14, 3, at::kDouble).requires_grad_(true);
  const at::Tensor b = randomImage(12, 14, 4, at::kDouble);
  const at::Tensor grad = torch::autograd::grad({ssimReference(a, b)}, {a})[0];
  const double h = 1e-6;
  for (const std::int64_t flat : {0L, 17L, 200L, 503L}) {
    at::Tensor plus = a.detach().clone(), minus = a.detach().clone();
    plus.view({-1})[flat] += h;
    minus.view({-1})[flat] -= h;
    const double fd =
        (ssimReference(plus, b).item<double>() - ssimReference(minus, b).item<double>()) / (2 * h);
    EXPECT_NEAR(grad.view({-1})[flat].item<double>(), fd, 1e-7) << "element " << flat;
  }
}

// The fused SSIM of a blurred pair on `device` against its definition (1e-5) and the reference
// composition on the CPU (value 1e-5, gradient 1e-3 of its largest element), at odd sizes
// (borders, partial blocks) and the training size.
void expectFusedSsimMatchesTheReference(const at::Device& device) {
  for (const auto& [H, W] : {std::pair<int, int>{45, 80}, {7, 5}, {450, 800}}) {
    const at::Tensor a_cpu = randomImage(H, W, 5);
    const at::Tensor b_cpu = (a_cpu * 0.7 + randomImage(H, W, 6) * 0.3).contiguous();
    const at::Tensor a = a_cpu.to(device).requires_grad_(true), b = b_cpu.to(device);
    ASSERT_TRUE(gaussians::ssimIsFused(a, b));
    const at::Tensor fused = ssim(a, b);
    const at::Tensor g_fused = torch::autograd::grad({fused * 2.0}, {a})[0];
    const at::Tensor a_ref = a_cpu.clone().requires_grad_(true);
    const at::Tensor ref = ssimReference(a_ref, b_cpu);
    const at::Tensor g_ref = torch::autograd::grad({ref * 2.0}, {a_ref})[0];
    EXPECT_NEAR(fused.item<double>(), directSsim(a_cpu, b_cpu), 1e-5) << H << "x" << W;
    EXPECT_NEAR(fused.item<double>(), ref.item<double>(), 1e-5) << H << "x" << W;
    const double scale = g_ref.abs().max().item<double>();
    EXPECT_LT((g_fused.cpu() - g_ref).abs().max().item<double>(), 1e-3 * scale) << H << "x" << W;
  }
}

TEST(ImageMetrics, FusedCpuSsimMatchesTheReferenceValueAndGradient) {
  expectFusedSsimMatchesTheReference(at::kCPU);
  // Double images and targets that need a gradient take the reference path.
  const at::Tensor t = randomImage(8, 8, 7);
  EXPECT_FALSE(gaussians::ssimIsFused(t.to(at::kDouble), t.to(at::kDouble)));
  EXPECT_FALSE(gaussians::ssimIsFused(t, t.clone().requires_grad_(true)));
}

TEST(ImageMetrics, FusedCudaSsimMatchesTheReferenceValueAndGradient) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  expectFusedSsimMatchesTheReference(at::Device(at::kCUDA, 0));
  // A target that needs a gradient takes the reference path.
  const at::Tensor t = randomImage(8, 8, 7).cuda().requires_grad_(true);
  EXPECT_FALSE(gaussians::ssimIsFused(t, t));
}

// rgbLoss, the training's RGB loss: on the CPU exactly the composition of the L1 term and the
// fused SSIM (the CPU trainings' bits); on CUDA one fused node with the composition's value and
// gradient (pixels where the render equals the target included: the L1 term's gradient is 0 there).
TEST(ImageMetrics, RgbLossIsTheCompositionOfL1AndSsim) {
  using gaussians::rgbLoss;
  at::manual_seed(3);
  const at::Tensor b = at::rand({37, 53, 3});
  at::Tensor a0 = at::rand({37, 53, 3});
  a0.narrow(0, 0, 5).copy_(b.narrow(0, 0, 5));  // equal rows
  const double lambda = 0.2;
  const auto composed = [&](const at::Tensor& a, const at::Tensor& t) {
    return (1 - lambda) * (a - t).abs().mean() + lambda * (1 - ssim(a, t));
  };
  const at::Tensor ref_a = a0.clone().requires_grad_(true);
  const at::Tensor ref = composed(ref_a, b);
  const at::Tensor ref_grad = torch::autograd::grad({ref}, {ref_a})[0];
  const at::Tensor cpu_a = a0.clone().requires_grad_(true);
  EXPECT_FALSE(gaussians::rgbLossIsFused(cpu_a, b));
  const at::Tensor cpu = rgbLoss(cpu_a, b, lambda);
  EXPECT_TRUE(at::equal(cpu, ref));
  EXPECT_TRUE(at::equal(torch::autograd::grad({cpu}, {cpu_a})[0], ref_grad));
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const at::Tensor cuda_a = a0.cuda().requires_grad_(true);
  EXPECT_TRUE(gaussians::rgbLossIsFused(cuda_a, b.cuda()));
  const at::Tensor cuda = rgbLoss(cuda_a, b.cuda(), lambda);
  EXPECT_NEAR(cuda.item<float>(), ref.item<float>(), 1e-6);
  const at::Tensor cuda_grad = torch::autograd::grad({cuda * 3.0}, {cuda_a})[0].cpu();
  EXPECT_TRUE(at::allclose(cuda_grad, ref_grad * 3.0, 1e-4, 1e-9))
      << (cuda_grad - ref_grad * 3.0).abs().max();
  EXPECT_EQ(cuda_grad.narrow(0, 0, 5).abs().max().item<float>() > 0, true)
      << "the SSIM term still reaches the equal rows";
}

}  // namespace
}  // namespace sadsplat
