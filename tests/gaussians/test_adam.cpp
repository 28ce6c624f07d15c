// The fused Adam step against the textbook formula written with tensor operations.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/adam.h"

#include "adam_math.h"

namespace sadsplat {
namespace {

using gaussians::adamStep;

// The reference: eight element-wise tensor operations, in double.
void textbookStep(at::Tensor& x, const at::Tensor& g, at::Tensor& m, at::Tensor& v, double lr,
                  std::int64_t step) {
  const double b1 = 0.9, b2 = 0.999, eps = 1e-15;
  m = m * b1 + g * (1 - b1);
  v = v * b2 + g * g * (1 - b2);
  const double c1 = 1 - std::pow(b1, double(step)), c2 = 1 - std::pow(b2, double(step));
  x = x - lr * ((m / c1) / ((v / c2).sqrt() + eps));
}

TEST(Adam, FusedStepMatchesTheTextbookFormulaOverSeveralSteps) {
  at::manual_seed(3);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  at::Tensor x = at::randn({257, 3}, opts), m = at::zeros_like(x), v = at::zeros_like(x);
  at::Tensor rx = x.clone(), rm = m.clone(), rv = v.clone();
  for (std::int64_t step = 1; step <= 5; ++step) {
    const at::Tensor g = at::randn({257, 3}, opts);
    adamStep(x, g, m, v, 0.01, step);
    textbookStep(rx, g, rm, rv, 0.01, step);
  }
  EXPECT_TRUE(at::allclose(x, rx, 1e-12, 1e-14));
  EXPECT_TRUE(at::allclose(m, rm, 1e-12, 1e-14));
  EXPECT_TRUE(at::allclose(v, rv, 1e-12, 1e-14));
}

TEST(Adam, FloatStepIsBitIdenticalToTheScalarUpdateOfEveryElement) {
  // 1027 elements: the vectorised loop's remainder too; every third gradient 0 (a Gaussian that
  // no view saw) and a step without any gradient.
  at::manual_seed(5);
  at::Tensor x = at::randn({1027}), m = at::zeros_like(x), v = at::zeros_like(x);
  std::vector<float> rx(x.data_ptr<float>(), x.data_ptr<float>() + x.numel());
  std::vector<float> rm(rx.size(), 0.f), rv(rx.size(), 0.f);
  const gaussians::AdamSettings settings;
  for (std::int64_t step = 1; step <= 4; ++step) {
    at::Tensor g = at::randn({1027}) * 3;
    g.view({-1}).slice(0, 0, 1027, 3).zero_();
    const bool without_gradient = step == 3;
    adamStep(x, without_gradient ? at::Tensor() : g, m, v, 0.05, step, settings);
    const auto c = gaussians::adam::coefficientsAt<float>(step, 0.05, settings.beta1,
                                                          settings.beta2, settings.eps);
    for (std::size_t i = 0; i < rx.size(); ++i) {
      gaussians::adam::update(&rx[i], without_gradient ? 0.f : g.data_ptr<float>()[i], &rm[i],
                              &rv[i], c);
    }
  }
  for (std::size_t i = 0; i < rx.size(); ++i) {
    ASSERT_EQ(x.data_ptr<float>()[i], rx[i]) << "value " << i;
    ASSERT_EQ(m.data_ptr<float>()[i], rm[i]) << "m " << i;
    ASSERT_EQ(v.data_ptr<float>()[i], rv[i]) << "v " << i;
  }
}

TEST(Adam, FirstStepMovesEachElementByTheLearningRateAgainstItsGradientSign) {
  at::Tensor x = at::zeros({4}), m = at::zeros({4}), v = at::zeros({4});
  const at::Tensor g = at::tensor({2.0f, -0.5f, 1e-3f, -7.0f});
  adamStep(x, g, m, v, 0.1, 1);
  // Step 1: m / (1 - b1) = g and sqrt(v / (1 - b2)) = |g|, so the update is lr * sign(g).
  EXPECT_TRUE(at::allclose(x, at::tensor({-0.1f, 0.1f, -0.1f, 0.1f}), 1e-5, 1e-6)) << x;
}

TEST(Adam, UndefinedGradientIsAZeroGradient) {
  at::manual_seed(5);
  at::Tensor x = at::randn({10}), m = at::randn({10}), v = at::rand({10});
  at::Tensor x2 = x.clone(), m2 = m.clone(), v2 = v.clone();
  adamStep(x, at::Tensor(), m, v, 0.05, 7);
  adamStep(x2, at::zeros({10}), m2, v2, 0.05, 7);
  EXPECT_TRUE(at::equal(x, x2));
  EXPECT_TRUE(at::equal(m, m2));
  EXPECT_TRUE(at::equal(v, v2));
  EXPECT_FALSE(at::equal(m, m2 / 0.9)) << "moments decay";
}

TEST(Adam, UpdatesALeafThatRequiresGradInPlace) {
  at::Tensor x = at::ones({3}).requires_grad_(true), m = at::zeros({3}), v = at::zeros({3});
  const void* storage = x.data_ptr();
  adamStep(x, at::ones({3}), m, v, 0.5, 1);
  EXPECT_EQ(x.data_ptr(), storage);
  EXPECT_TRUE(x.requires_grad());
  EXPECT_NEAR(x[0].item<float>(), 0.5f, 1e-6);
}

TEST(Adam, MismatchedMomentsAreAnError) {
  at::Tensor x = at::zeros({4}), m = at::zeros({5}), v = at::zeros({4});
  EXPECT_THROW(adamStep(x, at::zeros({4}), m, v, 0.1, 1), Error);
  at::Tensor m2 = at::zeros({4}, at::kDouble);
  EXPECT_THROW(adamStep(x, at::zeros({4}), m2, v, 0.1, 1), Error);
  at::Tensor m3 = at::zeros({4});
  EXPECT_THROW(adamStep(x, at::zeros({3}), m3, v, 0.1, 1), Error);
  EXPECT_THROW(adamStep(x, at::zeros({4}), m3, v, 0.1, 0), Error);
}

TEST(Adam, CudaStepMatchesTheCpuStep) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  at::manual_seed(9);
  at::Tensor x = at::randn({100003}), m = at::randn({100003}), v = at::rand({100003});
  const at::Tensor g = at::randn({100003});
  at::Tensor cx = x.cuda(), cm = m.cuda(), cv = v.cuda();
  adamStep(x, g, m, v, 0.01, 11);
  adamStep(cx, g.cuda(), cm, cv, 0.01, 11);
  EXPECT_TRUE(at::allclose(cx.cpu(), x, 1e-5, 1e-6));
  EXPECT_TRUE(at::allclose(cm.cpu(), m, 1e-5, 1e-7));
  EXPECT_TRUE(at::allclose(cv.cpu(), v, 1e-5, 1e-7));
  at::Tensor cx2 = x.cuda(), cm2 = m.cuda(), cv2 = v.cuda();
  adamStep(x, at::Tensor(), m, v, 0.01, 12);
  adamStep(cx2, at::Tensor(), cm2, cv2, 0.01, 12);
  EXPECT_TRUE(at::allclose(cx2.cpu(), x, 1e-5, 1e-6));
}

// Several tensors of different sizes, one without a gradient, more than one launch's worth.
std::vector<gaussians::AdamTensors> adamProblem(const at::Device& device) {
  at::manual_seed(9);
  std::vector<gaussians::AdamTensors> tensors;
  for (int k = 0; k < 19; ++k) {
    const std::int64_t n = 1 + (k * 7919) % 70000;
    gaussians::AdamTensors t;
    t.value = at::randn({n}).to(device);
    t.grad = k == 3 ? at::Tensor() : (at::randn({n}) * 1e-3).to(device);
    t.m = (at::randn({n}) * 1e-4).to(device);
    t.v = (at::rand({n}) * 1e-6).to(device);
    t.lr = 1e-3 * (k + 1);
    tensors.push_back(t);
  }
  return tensors;
}

void expectOneStepPerTensor(const at::Device& device) {
  std::vector<gaussians::AdamTensors> many = adamProblem(device), one = adamProblem(device);
  gaussians::adamSteps(many, 7);
  for (gaussians::AdamTensors& t : one) adamStep(t.value, t.grad, t.m, t.v, t.lr, 7);
  for (std::size_t k = 0; k < many.size(); ++k) {
    EXPECT_TRUE(at::equal(many[k].value, one[k].value)) << "tensor " << k;
    EXPECT_TRUE(at::equal(many[k].m, one[k].m)) << "tensor " << k;
    EXPECT_TRUE(at::equal(many[k].v, one[k].v)) << "tensor " << k;
  }
  EXPECT_FALSE(at::equal(many[18].value, adamProblem(device)[18].value));  // it moved
}

TEST(Adam, SeveralTensorsAtOnceGetTheValuesOfOneStepPerTensor) {
  expectOneStepPerTensor(at::Device(at::kCPU));
}

TEST(Adam, CudaStepOfSeveralTensorsInOneLaunchIsBitIdenticalToOneStepPerTensor) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  expectOneStepPerTensor(at::Device(at::kCUDA, 0));
}

}  // namespace
}  // namespace sadsplat
