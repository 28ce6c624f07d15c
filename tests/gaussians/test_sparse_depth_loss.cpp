// The sparse-depth loss: its value and gradient on a hand-made depth image.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/sparse_depth_loss.h"

namespace sadsplat {
namespace {

TEST(SparseDepthLoss, IsTheMeanRelativeDepthDifferenceAtThePoints) {
  // A 4 x 4 depth image of 10 with 12 at pixel 5; points seen at pixel 5 (depth 10) and pixel 0
  // (depth 8): (|12 - 10| / 10 + |10 - 8| / 8) / 2 = (0.2 + 0.25) / 2.
  at::Tensor depth = at::full({4, 4}, 10.0, at::kDouble);
  depth.view({-1})[5] = 12.0;
  depth.requires_grad_(true);
  gaussians::SparseDepthSamples s;
  s.pixels = at::tensor({5, 0}, at::kLong);
  s.depths = at::tensor({10.0f, 8.0f}, at::kFloat);
  const at::Tensor loss = gaussians::sparseDepthLoss(depth, s);
  EXPECT_NEAR(loss.item<double>(), 0.225, 1e-12);
  loss.backward();
  // d/dD of |D - z| / z / 2: sign(D - z) / (2 z) at the samples' pixels, 0 elsewhere.
  const at::Tensor g = depth.grad().view({-1});
  EXPECT_NEAR(g[5].item<double>(), 1.0 / 20, 1e-12);
  EXPECT_NEAR(g[0].item<double>(), 1.0 / 16, 1e-12);
  EXPECT_NEAR(g.abs().sum().item<double>(), 1.0 / 20 + 1.0 / 16, 1e-12);
  // A point behind the rendered surface pulls it back: the gradient's sign turns.
  s.depths = at::tensor({13.0f}, at::kFloat);
  s.pixels = at::tensor({5}, at::kLong);
  depth.grad().zero_();
  gaussians::sparseDepthLoss(depth, s).backward();
  EXPECT_NEAR(depth.grad().view({-1})[5].item<double>(), -1.0 / 13, 1e-7);
}

TEST(SparseDepthLoss, WithoutSamplesIsZeroAndAWrongImageIsAnError) {
  EXPECT_EQ(gaussians::sparseDepthLoss(at::ones({4, 4}), {}).item<double>(), 0.0);
  gaussians::SparseDepthSamples s;
  s.pixels = at::tensor({0}, at::kLong);
  s.depths = at::tensor({1.0f}, at::kFloat);
  EXPECT_THROW(gaussians::sparseDepthLoss(at::ones({1, 4, 4}), s), Error);
}

}  // namespace
}  // namespace sadsplat
