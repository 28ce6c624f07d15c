// Counter-based uniforms: in (0, 1), deterministic, different per key, statistically uniform.
#include <gtest/gtest.h>

#include "sadsplat/gaussians/counter_random.h"

namespace sadsplat {
namespace {

using gaussians::counterUniform;

TEST(CounterRandom, SameKeySameNumbersOtherKeyOtherNumbers) {
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  const at::Tensor a = counterUniform(1000, 42, 13, 7, opts);
  EXPECT_TRUE(at::equal(a, counterUniform(1000, 42, 13, 7, opts)));
  EXPECT_TRUE(at::equal(a.slice(0, 0, 10), counterUniform(10, 42, 13, 7, opts)))
      << "element i does not depend on n";
  for (const at::Tensor& other :
       {counterUniform(1000, 43, 13, 7, opts), counterUniform(1000, 42, 14, 7, opts),
        counterUniform(1000, 42, 13, 8, opts)}) {
    EXPECT_LT((a == other).sum().item<int64_t>(), 5);
  }
}

TEST(CounterRandom, OpenUnitIntervalAndUniformMoments) {
  const at::Tensor u = counterUniform(200000, 1, 2, 3, at::TensorOptions().dtype(at::kDouble));
  EXPECT_GT(u.min().item<double>(), 0.0);
  EXPECT_LT(u.max().item<double>(), 1.0);
  EXPECT_NEAR(u.mean().item<double>(), 0.5, 0.005);
  EXPECT_NEAR(u.var().item<double>(), 1.0 / 12, 0.002);
  // Ten equal bins hold 10 % each within a few standard deviations (sd ~ 0.07 %).
  const at::Tensor bins = at::histc(u, 10, 0, 1) / 200000.0;
  EXPECT_LT((bins - 0.1).abs().max().item<double>(), 0.004) << bins;
  // Neighbours are uncorrelated.
  const at::Tensor x = u.slice(0, 0, -1) - 0.5, y = u.slice(0, 1) - 0.5;
  EXPECT_LT(std::abs((x * y).mean().item<double>()) * 12, 0.01);
}

// The per-element form that kernels use gives the tensor draw's numbers, bit for bit.
TEST(CounterRandom, OneElementAtATimeGivesTheTensorNumbers) {
  const at::Tensor u = counterUniform(3000, 42, 13, 7, at::TensorOptions().dtype(at::kFloat));
  const gaussians::CounterKey key = gaussians::counterKey(42, 13, 7);
  for (std::int64_t i = 0; i < 3000; ++i) {
    ASSERT_EQ(gaussians::counterUniformAt(key, i), u[i].item<float>()) << i;
  }
}

TEST(CounterRandom, CudaGivesTheCpuNumbers) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const auto cpu = at::TensorOptions().dtype(at::kFloat);
  EXPECT_TRUE(at::equal(counterUniform(5000, 9, 1, 2, cpu),
                        counterUniform(5000, 9, 1, 2, cpu.device(at::kCUDA)).cpu()));
}

}  // namespace
}  // namespace sadsplat
