// Cloud <-> tensors: lossless both ways, on CPU and (where present) CUDA.
#include <gtest/gtest.h>

#include <ATen/Context.h>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/gaussian_tensors.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

void expectLosslessOn(const at::Device& device) {
  const auto cloud = test::randomGaussians(300, 31);
  const auto tensors = gaussians::fromCloud(cloud, device);
  EXPECT_EQ(tensors.means.device(), device);
  EXPECT_EQ(tensors.size(), 300);
  const auto back = gaussians::toCloud(tensors);
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_TRUE(bitwiseEqual(back[i], cloud[i])) << i;

  // And tensors -> cloud -> tensors.
  const auto again = gaussians::fromCloud(back, device);
  EXPECT_TRUE(at::equal(again.sh_rest, tensors.sh_rest));
  EXPECT_TRUE(at::equal(again.labels, tensors.labels));
}

TEST(GaussianTensors, CloudRoundTripIsLosslessOnCpu) { expectLosslessOn(at::kCPU); }

TEST(GaussianTensors, CloudRoundTripIsLosslessOnCuda) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device in this build or machine";
  expectLosslessOn(at::Device(at::kCUDA, 0));
}

TEST(GaussianTensors, UsesTheReferenceTrainerLayouts) {
  auto cloud = test::randomGaussians(2, 32);
  const auto t = gaussians::fromCloud(cloud);
  EXPECT_EQ(t.sh_dc.sizes(), (std::vector<int64_t>{2, 1, 3}));
  EXPECT_EQ(t.sh_rest.sizes(), (std::vector<int64_t>{2, 15, 3}));
  // sh_rest[i, k, c] is the point's channel-major f_rest[c * 15 + k].
  EXPECT_EQ(t.sh_rest[1][4][2].item<float>(), cloud[1].f_rest[2 * 15 + 4]);
  EXPECT_EQ(t.rotations[0][0].item<float>(), cloud[0].rot[0]);
  cloud[0].label = kUnlabelled;
  cloud[1].label = 3;
  const auto l = gaussians::fromCloud(cloud).labels;
  EXPECT_EQ(l[0].item<int64_t>(), -1);
  EXPECT_EQ(l[1].item<int64_t>(), 3);
}

TEST(GaussianTensors, ShorterFeaturesArePaddedAndBadShapesRejected) {
  const auto cloud = test::randomGaussians(4, 33);
  auto t = gaussians::fromCloud(cloud, at::kCPU, 8);
  EXPECT_EQ(t.features.size(1), 8);
  const auto back = gaussians::toCloud(t);
  EXPECT_EQ(back[2].feature[7], cloud[2].feature[7]);
  EXPECT_EQ(back[2].feature[8], 0.f);

  t.rotations = at::zeros({4, 3});
  try {
    gaussians::toCloud(t);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "rotations");
  }
  EXPECT_THROW(gaussians::fromCloud(cloud, at::kCPU, 33), Error);
}

}  // namespace
}  // namespace sadsplat
