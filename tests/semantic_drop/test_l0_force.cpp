// The balanced rule's L0 force: values by hand on the CPU, the CUDA kernels against the ATen
// reference.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/semantic_drop/l0_force.h"

namespace sadsplat {
namespace {

using semantic_drop::addBalancedL0Force;
using semantic_drop::addBalancedL0ForceReference;

TEST(L0Force, ReachedGaussiansGetTheDirectionScaledToTheMeanLossGradient) {
  // Reached: 0 and 2 (opacity gradient != 0). sum |grad| = 0.2 + 0.6 = 0.8, sum direction =
  // 0.25 + 0.15 = 0.4: scale 2, strength 0.5 -> force = direction.
  at::Tensor grad = at::tensor({0.2f, -5.0f, -0.6f});
  const at::Tensor direction = at::tensor({0.25f, 0.2f, 0.15f});
  const at::Tensor opacity_grad = at::tensor({1e-3f, 0.0f, -2.0f});
  addBalancedL0Force(grad, direction, opacity_grad, at::Tensor(), 0.5);
  EXPECT_NEAR(grad[0].item<float>(), 0.2f + 0.25f, 1e-6);
  EXPECT_EQ(grad[1].item<float>(), -5.0f);
  EXPECT_NEAR(grad[2].item<float>(), -0.6f + 0.15f, 1e-6);
  // Weights multiply each force; nothing reached: no force.
  at::Tensor weighted = at::tensor({0.2f, -5.0f, -0.6f});
  addBalancedL0Force(weighted, direction, opacity_grad, at::tensor({2.0f, 3.0f, 0.0f}), 0.5);
  EXPECT_NEAR(weighted[0].item<float>(), 0.2f + 0.5f, 1e-6);
  EXPECT_NEAR(weighted[2].item<float>(), -0.6f, 1e-6);
  at::Tensor untouched = at::tensor({0.2f, -5.0f, -0.6f});
  addBalancedL0Force(untouched, direction, at::zeros({3}), at::Tensor(), 0.5);
  EXPECT_TRUE(at::equal(untouched, at::tensor({0.2f, -5.0f, -0.6f})));
  EXPECT_THROW(addBalancedL0Force(grad, at::zeros({2}), opacity_grad, at::Tensor(), 0.5), Error);
}

TEST(L0Force, CudaKernelsMatchTheReference) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(5);
  const int n = 300007;
  const at::Tensor grad = at::randn({n}) * 1e-4;
  const at::Tensor direction = at::rand({n}) * 0.25;
  // A third of the Gaussians not reached.
  const at::Tensor opacity_grad = at::randn({n}) * (at::rand({n}) > 0.33).to(at::kFloat);
  const at::Tensor weights = at::rand({n}) * 2;
  for (const bool weighted : {false, true}) {
    at::Tensor cpu = grad.clone(), gpu = grad.cuda();
    const at::Tensor w = weighted ? weights : at::Tensor();
    addBalancedL0ForceReference(cpu, direction, opacity_grad, w, 0.7);
    addBalancedL0Force(gpu, direction.cuda(), opacity_grad.cuda(),
                       weighted ? weights.cuda() : at::Tensor(), 0.7);
    EXPECT_TRUE(at::allclose(gpu.cpu(), cpu, 1e-4, 1e-9)) << "weighted " << weighted;
    EXPECT_FALSE(at::allclose(cpu, grad, 1e-4, 1e-9));  // the force is not negligible
  }
}

}  // namespace
}  // namespace sadsplat
