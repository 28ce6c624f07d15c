// The semantic loss: its definition on hand-computed pixels, the reference's gradient against
// finite differences, and the fused CUDA kernels against the reference (value and gradients).
#include "sadsplat/gaussians/semantic_loss.h"

#include <gtest/gtest.h>

#include <torch/csrc/autograd/autograd.h>

#include <algorithm>
#include <string>
#include <tuple>
#include <vector>

namespace sadsplat {
namespace {

using gaussians::semanticLoss;
using gaussians::semanticLossReference;

TEST(SemanticLoss, UnsupervisedPixelsGiveNoGradientAndNoValue) {
  at::manual_seed(3);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  at::Tensor features = at::randn({2, 3, 4}, opts).requires_grad_(true);
  const at::Tensor labels =
      at::tensor({1, -1, 0, -1, -1, 2}, at::TensorOptions().dtype(at::kLong)).view({2, 3});
  const at::Tensor W = at::randn({3, 4}, opts), b = at::randn({3}, opts);
  const at::Tensor loss = semanticLoss(features, labels, W, b);
  // By hand: mean over the three supervised pixels of 1 - logit[c] / |logit|.
  double want = 0;
  for (auto [y, x, c] : std::vector<std::tuple<int, int, int>>{{0, 0, 1}, {0, 2, 0}, {1, 2, 2}}) {
    const at::Tensor logit = at::linear(features[y][x].detach(), W, b);
    want += (1 - logit[c].item<double>() / logit.norm().item<double>()) / 3;
  }
  EXPECT_NEAR(loss.item<double>(), want, 1e-12);
  const at::Tensor grad = torch::autograd::grad({loss}, {features})[0];
  EXPECT_EQ(grad[0][1].abs().sum().item<double>(), 0.0);
  EXPECT_EQ(grad[1][0].abs().sum().item<double>(), 0.0);
  EXPECT_EQ(grad[1][1].abs().sum().item<double>(), 0.0);
  EXPECT_GT(grad[0][0].abs().sum().item<double>(), 0.0);
  EXPECT_GT(grad[1][2].abs().sum().item<double>(), 0.0);
}

TEST(SemanticLoss, DecoderGradientMatchesFiniteDifferences) {
  at::manual_seed(4);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const at::Tensor features = at::randn({3, 4, 5}, opts);
  const at::Tensor labels = at::randint(-1, 3, {3, 4}, at::TensorOptions().dtype(at::kLong));
  const at::Tensor W = at::randn({3, 5}, opts).requires_grad_(true);
  const at::Tensor b = at::randn({3}, opts).requires_grad_(true);
  const auto grads = torch::autograd::grad({semanticLossReference(features, labels, W, b)}, {W, b});
  const double h = 1e-6;
  for (int k = 0; k < 15; ++k) {
    const at::Tensor plus = W.detach().clone(), minus = W.detach().clone();
    plus.view({-1})[k] += h;
    minus.view({-1})[k] -= h;
    const double fd = (semanticLossReference(features, labels, plus, b).item<double>() -
                       semanticLossReference(features, labels, minus, b).item<double>()) /
                      (2 * h);
    EXPECT_NEAR(grads[0].view({-1})[k].item<double>(), fd, 1e-7) << "W element " << k;
  }
  for (int k = 0; k < 3; ++k) {
    const at::Tensor plus = b.detach().clone(), minus = b.detach().clone();
    plus[k] += h;
    minus[k] -= h;
    const double fd = (semanticLossReference(features, labels, W, plus).item<double>() -
                       semanticLossReference(features, labels, W, minus).item<double>()) /
                      (2 * h);
    EXPECT_NEAR(grads[1][k].item<double>(), fd, 1e-7) << "b element " << k;
  }
}

TEST(SemanticLoss, CpuTensorsTakeTheReferencePath) {
  const at::Tensor f = at::zeros({2, 2, 4}), l = at::zeros({2, 2}, at::kLong);
  EXPECT_FALSE(gaussians::semanticLossIsFused(f, l, at::zeros({3, 4}), at::zeros({3})));
}

// Fused (CUDA) against the reference (CPU, float64) for H x W pixels, D channels, C classes.
// Strided: the features are channels 3.. of a [H, W, 3 + D] image, as the rasterizer returns them.
void expectFusedMatchesReference(int H, int W, int D, int C, bool decoder_grad,
                                 double unsupervised_fraction, bool strided = false) {
  at::manual_seed(11);
  const at::Tensor f_cpu = at::randn({H, W, D});
  at::Tensor l_cpu = at::randint(0, C, {H, W}, at::TensorOptions().dtype(at::kLong));
  l_cpu = at::where(at::rand({H, W}) < unsupervised_fraction, at::full_like(l_cpu, -1), l_cpu);
  const at::Tensor w_cpu = at::randn({C, D}) * 0.3, b_cpu = at::randn({C}) * 0.1;

  const at::Tensor image =
      (strided ? at::cat({at::randn({H, W, 3}), f_cpu}, 2) : f_cpu).cuda().requires_grad_(true);
  const at::Tensor f = strided ? image.slice(2, 3, 3 + D) : image, l = l_cpu.cuda();
  const at::Tensor w = w_cpu.cuda().requires_grad_(decoder_grad);
  const at::Tensor b = b_cpu.cuda().requires_grad_(decoder_grad);
  ASSERT_TRUE(gaussians::semanticLossIsFused(f, l, w, b));
  const at::Tensor fused = semanticLoss(f, l, w, b);
  std::vector<at::Tensor> inputs{image};
  if (decoder_grad) inputs = {image, w, b};
  // Scaled by 2: the upstream gradient must reach every output.
  auto g_fused = torch::autograd::grad({fused * 2.0}, inputs);
  if (strided) {
    EXPECT_EQ(g_fused[0].slice(2, 0, 3).abs().sum().item<double>(), 0.0);
    g_fused[0] = g_fused[0].slice(2, 3, 3 + D);
  }

  const at::Tensor f_ref = f_cpu.to(at::kDouble).requires_grad_(true);
  const at::Tensor w_ref = w_cpu.to(at::kDouble).requires_grad_(true);
  const at::Tensor b_ref = b_cpu.to(at::kDouble).requires_grad_(true);
  const at::Tensor ref = semanticLossReference(f_ref, l_cpu, w_ref, b_ref);
  const auto g_ref = torch::autograd::grad({ref * 2.0}, {f_ref, w_ref, b_ref});

  const std::string where = std::to_string(H) + "x" + std::to_string(W) +
                            " D=" + std::to_string(D) + " C=" + std::to_string(C);
  EXPECT_NEAR(fused.item<double>(), ref.item<double>(), 1e-5) << where;
  for (std::size_t k = 0; k < g_fused.size(); ++k) {
    const at::Tensor want = g_ref[k];
    const double scale = std::max(want.abs().max().item<double>(), 1e-12);
    const double err = (g_fused[k].cpu().to(at::kDouble) - want).abs().max().item<double>();
    EXPECT_LT(err, 1e-4 * scale) << where << " gradient " << k;
  }
  // Unsupervised pixels get exactly zero gradient.
  const at::Tensor unset = (l_cpu < 0).unsqueeze(2).expand({H, W, D});
  EXPECT_EQ(g_fused[0].cpu().masked_select(unset).abs().sum().item<double>(), 0.0) << where;
}

TEST(SemanticLoss, FusedCudaMatchesTheReferenceValueAndGradients) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  expectFusedMatchesReference(45, 80, 32, 6, true, 0.3);         // the training case
  expectFusedMatchesReference(7, 5, 32, 16, false, 0.5);         // a frozen decoder, partial block
  expectFusedMatchesReference(33, 17, 24, 11, true, 0.1);        // fewer channels than lanes
  expectFusedMatchesReference(450, 800, 32, 8, true, 0.6);       // a full view
  expectFusedMatchesReference(45, 80, 32, 6, true, 0.3, true);   // the rasterizer's slice
  expectFusedMatchesReference(9, 13, 32, 16, false, 0.2, true);  // strided, most classes
}

TEST(SemanticLoss, MoreChannelsOrClassesThanTheKernelsHoldTakeTheReferencePath) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const auto cuda = at::TensorOptions().device(at::kCUDA);
  const at::Tensor l = at::zeros({2, 2}, cuda.dtype(at::kLong));
  EXPECT_FALSE(gaussians::semanticLossIsFused(at::zeros({2, 2, 33}, cuda), l,
                                              at::zeros({3, 33}, cuda), at::zeros({3}, cuda)));
  EXPECT_FALSE(gaussians::semanticLossIsFused(at::zeros({2, 2, 32}, cuda), l,
                                              at::zeros({17, 32}, cuda), at::zeros({17}, cuda)));
  EXPECT_TRUE(gaussians::semanticLossIsFused(at::zeros({2, 2, 32}, cuda), l,
                                             at::zeros({16, 32}, cuda), at::zeros({16}, cuda)));
}

TEST(SemanticLoss, FusedCudaWithNoSupervisedPixelIsZeroWithZeroGradient) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const at::Tensor f = at::randn({9, 11, 32}).cuda().requires_grad_(true);
  const at::Tensor l = at::full({9, 11}, -1, at::TensorOptions().dtype(at::kLong)).cuda();
  const at::Tensor w = at::randn({5, 32}).cuda().requires_grad_(true);
  const at::Tensor b = at::randn({5}).cuda().requires_grad_(true);
  const at::Tensor loss = semanticLoss(f, l, w, b);
  EXPECT_EQ(loss.item<double>(), 0.0);
  for (const at::Tensor& g : torch::autograd::grad({loss}, {f, w, b}))
    EXPECT_EQ(g.abs().sum().item<double>(), 0.0);
}

}  // namespace
}  // namespace sadsplat
