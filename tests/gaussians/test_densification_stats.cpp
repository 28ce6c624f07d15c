// The densification statistics of one render: values by hand on the CPU, the CUDA kernel against
// the ATen reference.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/densification_stats.h"

namespace sadsplat {
namespace {

using gaussians::accumulateScreenGradients;
using gaussians::accumulateScreenGradientsReference;

TEST(DensificationStats, SeenGaussiansGetTheirScaledGradientLengthAndRadius) {
  // Gaussian 0 seen (radius 3): |(0.3 * 2, 0.4 * 0.5)| = |(0.6, 0.2)|; Gaussian 1 unseen.
  const at::Tensor grad = at::tensor({0.3f, 0.4f, 5.0f, 5.0f}).view({2, 2});
  const at::Tensor radii = at::tensor({3, 0}, at::kInt);
  at::Tensor accum = at::tensor({1.0f, 2.0f}), denom = at::tensor({4.0f, 7.0f});
  at::Tensor max_radii = at::tensor({5.0f, 9.0f});
  accumulateScreenGradients(grad, radii, 2.0, 0.5, accum, denom, max_radii);
  EXPECT_NEAR(accum[0].item<float>(), 1.0f + std::sqrt(0.36f + 0.04f), 1e-6);
  EXPECT_EQ(accum[1].item<float>(), 2.0f);
  EXPECT_EQ(denom[0].item<float>(), 5.0f);
  EXPECT_EQ(denom[1].item<float>(), 7.0f);
  EXPECT_EQ(max_radii[0].item<float>(), 5.0f);  // 3 < 5: kept
  EXPECT_EQ(max_radii[1].item<float>(), 9.0f);
  accumulateScreenGradients(grad, at::tensor({8, 0}, at::kInt), 2.0, 0.5, accum, denom,
                            max_radii);
  EXPECT_EQ(max_radii[0].item<float>(), 8.0f);
  at::Tensor short_denom = at::zeros({1});
  EXPECT_THROW(accumulateScreenGradients(grad, radii, 1, 1, accum, short_denom, max_radii), Error);
}

TEST(DensificationStats, CudaKernelMatchesTheReference) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(4);
  const int n = 100003;
  const at::Tensor grad = at::randn({n, 2}) * 1e-3;
  const at::Tensor radii = (at::randint(-3, 40, {n}).clamp_min(0)).to(at::kInt);
  at::Tensor accum = at::rand({n}), denom = at::randint(0, 5, {n}).to(at::kFloat);
  at::Tensor max_radii = at::randint(0, 30, {n}).to(at::kFloat);
  at::Tensor c_accum = accum.cuda(), c_denom = denom.cuda(), c_max = max_radii.cuda();
  accumulateScreenGradientsReference(grad, radii, 400.0, 225.0, accum, denom, max_radii);
  accumulateScreenGradients(grad.cuda(), radii.cuda(), 400.0, 225.0, c_accum, c_denom, c_max);
  EXPECT_TRUE(at::allclose(c_accum.cpu(), accum, 1e-5, 1e-6));
  EXPECT_TRUE(at::equal(c_denom.cpu(), denom));
  EXPECT_TRUE(at::equal(c_max.cpu(), max_radii));
}

}  // namespace
}  // namespace sadsplat
