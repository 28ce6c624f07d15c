// Blending-weight sums (the recovery phase's pruning score) against the rendered alpha: per
// pixel the blending weights of all Gaussians add up to the accumulated alpha, so their sums over
// the pixels add up to the alpha image's sum.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/contribution.h"
#include "test_support/photo_camera.h"

namespace sadsplat {
namespace {

using gaussians::GaussianParams;
using gaussians::RasterCamera;
using test::smallPhotoCamera;

// Isotropic Gaussians at `centres` (x, y, z triples) with scale 0.3 and opacity 0.8.
GaussianParams gaussiansAt(const std::vector<float>& centres) {
  const std::int64_t n = static_cast<std::int64_t>(centres.size() / 3);
  GaussianParams g;
  g.means = at::tensor(centres, at::kFloat).view({n, 3});
  g.quats = at::zeros({n, 4}, at::kFloat);
  g.quats.select(1, 0).fill_(1);
  g.log_scales = at::full({n, 3}, std::log(0.3f), at::kFloat);
  g.opacity_logits = at::full({n}, std::log(0.8f / 0.2f), at::kFloat);
  g.sh = at::full({n, 1, 3}, 0.5f, at::kFloat);
  return g;
}

double alphaSum(const GaussianParams& g, const RasterCamera& c) {
  gaussians::RenderSettings s;
  s.sh_degree = 0;
  s.features = false;
  s.depth = false;
  return gaussians::render(g, c, s).alpha.sum().item<double>();
}

TEST(Contribution, ScoresSumToTheRenderedAlphaAndHiddenOrUnseenGaussiansScoreZero) {
  // In front; right behind it (partly hidden); behind the camera; far outside the image.
  const GaussianParams g = gaussiansAt({0, 0, 5, 0, 0, 8, 0, 0, -5, 40, 0, 5});
  const at::Tensor score = gaussians::blendingWeightSums(g, {smallPhotoCamera()});
  ASSERT_EQ(score.size(0), 4);
  EXPECT_GT(score[0].item<double>(), 10.0);  // covers many pixels at up to 0.8
  EXPECT_GT(score[1].item<double>(), 0.0);
  EXPECT_LT(score[1].item<double>(), score[0].item<double>());  // behind the first
  EXPECT_EQ(score[2].item<double>(), 0.0);
  EXPECT_EQ(score[3].item<double>(), 0.0);
  EXPECT_NEAR(score.sum().item<double>(), alphaSum(g, smallPhotoCamera()),
              1e-3 * alphaSum(g, smallPhotoCamera()));

  // Alone, a Gaussian's score is its alpha image's sum.
  const GaussianParams one = gaussiansAt({0, 0, 8});
  EXPECT_NEAR(gaussians::blendingWeightSums(one, {smallPhotoCamera()})[0].item<double>(),
              alphaSum(one, smallPhotoCamera()), 1e-3 * alphaSum(one, smallPhotoCamera()));
}

TEST(Contribution, SumsOverTheViewsAndAppliesTheGate) {
  GaussianParams g = gaussiansAt({0, 0, 5, 1, 0, 6});
  const at::Tensor a = gaussians::blendingWeightSums(g, {smallPhotoCamera(0)});
  const at::Tensor b = gaussians::blendingWeightSums(g, {smallPhotoCamera(1)});
  const at::Tensor both =
      gaussians::blendingWeightSums(g, {smallPhotoCamera(0), smallPhotoCamera(1)});
  EXPECT_TRUE(at::allclose(both, a + b, 1e-5, 1e-4));
  // A closed gate: the Gaussian renders nothing and scores 0; the other one is no longer hidden.
  g.opacity_gate = at::tensor({0.0f, 1.0f});
  const at::Tensor gated = gaussians::blendingWeightSums(g, {smallPhotoCamera(0)});
  EXPECT_EQ(gated[0].item<double>(), 0.0);
  EXPECT_GT(gated[1].item<double>(), a[1].item<double>());
}

// Alone, a Gaussian's blending weight at a pixel is the rendered alpha there: its weighted sum of
// any per-pixel values is sum_p alpha(p) values(p, k), computed here from the alpha image.
TEST(WeightedPixelSums, AreTheAlphaWeightedSumsOfTheValuesForOneGaussian) {
  const GaussianParams one = gaussiansAt({0.2f, -0.1f, 6});
  const RasterCamera c = smallPhotoCamera();
  gaussians::RenderSettings s;
  s.sh_degree = 0;
  s.features = false;
  s.depth = false;
  const at::Tensor alpha = gaussians::render(one, c, s).alpha.to(at::kDouble);
  // Three channels: 1, the column index, a step that is 1 on the left half only.
  const at::Tensor column =
      at::arange(c.width, at::kDouble).view({1, c.width}).expand({c.height, c.width});
  const at::Tensor left = (column < c.width / 2).to(at::kDouble);
  const at::Tensor values = at::stack({at::ones_like(column), column, left}, 2).to(at::kFloat);
  const at::Tensor sums = gaussians::weightedPixelSums(one, c, values).to(at::kDouble);
  ASSERT_EQ(sums.sizes(), (at::IntArrayRef{1, 3}));
  for (int k = 0; k < 3; ++k) {
    const double expected = (alpha * values.select(2, k).to(at::kDouble)).sum().item<double>();
    EXPECT_NEAR(sums[0][k].item<double>(), expected, 1e-3 * std::abs(expected) + 1e-4) << k;
  }
  // The Gaussian sits right of the middle: more of its weight on the right half.
  EXPECT_LT(sums[0][2].item<double>(), 0.5 * sums[0][0].item<double>());
  EXPECT_THROW(gaussians::weightedPixelSums(one, c, values.narrow(0, 0, 10)), Error);
}

// Two Gaussians side by side, a class map that gives the left half class 0 and the right half
// class 1, and a hidden third one behind the left: each visible Gaussian's weight goes mostly to
// the class of its side; per camera the classes' weights add up to blendingWeightSums over the
// labelled pixels; pixels without a class (-1 or >= the count) count for none.
TEST(ClassWeightSums, GiveEachGaussianTheClassesOfThePixelsItDraws) {
  const GaussianParams g = gaussiansAt({-1.5f, 0, 5, 1.5f, 0, 5, -1.5f, 0, 30});
  const RasterCamera c = smallPhotoCamera();
  const at::Tensor column =
      at::arange(c.width, at::kLong).view({1, c.width}).expand({c.height, c.width});
  const at::Tensor halves = (column >= c.width / 2).to(at::kLong).contiguous();
  const at::Tensor w = gaussians::classWeightSums(
      g, {c}, [&](std::size_t) { return halves; }, 2);
  ASSERT_EQ(w.sizes(), (at::IntArrayRef{3, 2}));
  EXPECT_GT(w[0][0].item<double>(), 20 * w[0][1].item<double>());  // left Gaussian: class 0
  EXPECT_GT(w[1][1].item<double>(), 20 * w[1][0].item<double>());  // right Gaussian: class 1
  EXPECT_LT(w[2].sum().item<double>(), 0.05 * w[0].sum().item<double>());  // hidden behind
  const at::Tensor total = gaussians::blendingWeightSums(g, {c});
  EXPECT_TRUE(at::allclose(w.sum(1), total, 1e-4, 1e-3));
  // No class on the right half: the right Gaussian keeps only what it draws on the left.
  const at::Tensor left_only = at::where(halves == 1, at::full_like(halves, -1), halves);
  const at::Tensor l = gaussians::classWeightSums(
      g, {c, c},
      [&](std::size_t k) {
        return k == 0 ? left_only : at::full_like(halves, 7);  // camera 1: no pixel has a class
      },
      2);
  EXPECT_NEAR(l[1][0].item<double>(), w[1][0].item<double>(), 1e-4);
  EXPECT_EQ(l[1][1].item<double>(), 0.0);
  EXPECT_THROW(gaussians::classWeightSums(
                   g, {c}, [&](std::size_t) { return halves; }, 0),
               Error);
  EXPECT_THROW(gaussians::classWeightSums(
                   g, {c}, [&](std::size_t) { return halves.t(); }, 2),
               Error);
}

// The rendered depth map of the Gaussians themselves (what Trainer::renderedDepthResiduals uses).
at::Tensor depthOf(const GaussianParams& g, const RasterCamera& c) {
  gaussians::RenderSettings s;
  s.sh_degree = 0;
  s.features = false;
  return gaussians::render(g, c, s).depth;
}

// Alone, a Gaussian is the surface: every pixel it draws renders its own depth, gap 0. A faint
// Gaussian floating in front of an opaque wall draws where the rendered depth is mostly the
// wall's: its gap is most of the distance between them, the wall's small. A Gaussian no camera
// draws has no gap (+inf). Over several cameras the gaps average by the Gaussian's weights.
TEST(DepthResiduals, AreTheGapsToTheRenderedSurfaceWhereEachGaussianDraws) {
  const RasterCamera c = smallPhotoCamera();
  const GaussianParams one = gaussiansAt({0.1f, 0, 6});
  const at::Tensor alone =
      gaussians::depthResiduals(one, {c}, [&](std::size_t) { return depthOf(one, c); });
  EXPECT_LT(alone[0].item<double>(), 1e-3);

  GaussianParams g = gaussiansAt({0, 0, 8, 0, 0, 3, 0, 0, -5});
  g.log_scales[0].fill_(std::log(3.0f));               // a wide wall
  g.opacity_logits[0].fill_(std::log(0.99f / 0.01f));  // opaque
  g.opacity_logits[1].fill_(std::log(0.2f / 0.8f));    // a faint floater, 5 in front
  const at::Tensor gap =
      gaussians::depthResiduals(g, {c}, [&](std::size_t) { return depthOf(g, c); });
  ASSERT_EQ(gap.size(0), 3);
  EXPECT_GT(gap[1].item<double>(), 2.5);           // the floater: far from what is rendered there
  EXPECT_LT(gap[1].item<double>(), 5.0);           // but not beyond the wall
  EXPECT_LT(gap[0].item<double>(), 0.5);           // the wall
  EXPECT_TRUE(std::isinf(gap[2].item<double>()));  // behind the camera

  // Over two cameras the gaps average by how much each Gaussian draws in each (its
  // blendingWeightSums there).
  const RasterCamera side = smallPhotoCamera(3);
  const at::Tensor gap_side =
      gaussians::depthResiduals(g, {side}, [&](std::size_t) { return depthOf(g, side); });
  const at::Tensor both = gaussians::depthResiduals(
      g, {c, side}, [&](std::size_t k) { return depthOf(g, k == 0 ? c : side); });
  const at::Tensor w0 = gaussians::blendingWeightSums(g, {c});
  const at::Tensor w1 = gaussians::blendingWeightSums(g, {side});
  for (int i = 0; i < 2; ++i) {
    // (A camera that does not draw the Gaussian adds nothing: its gap alone is +inf.)
    const double a = w0[i].item<double>(), b = w1[i].item<double>();
    const double expected = ((a > 0 ? gap[i].item<double>() * a : 0.0) +
                             (b > 0 ? gap_side[i].item<double>() * b : 0.0)) /
                            (a + b);
    EXPECT_NEAR(both[i].item<double>(), expected, 1e-3 * expected + 1e-5) << i;
  }
  EXPECT_THROW(gaussians::depthResiduals(g, {c}, [&](std::size_t) { return depthOf(g, c).t(); }),
               Error);
}

// The L0 term's weights, by hand: w = (1 + c / median c)^-gamma / mean.
TEST(InverseContributionWeights, FallWithTheContributionAndAverageOne) {
  // Sorted [0, 1, 1, 3]: the median (lower middle value) is 1; gamma 1 gives 1, 1/2, 1/2, 1/4
  // (mean 9/16) before the scaling.
  const at::Tensor w =
      gaussians::inverseContributionWeights(at::tensor({0.0f, 1.0f, 3.0f, 1.0f}), 1.0);
  const float k = 16.0f / 9.0f;
  EXPECT_TRUE(at::allclose(w, at::tensor({k, k / 2, k / 4, k / 2}), 1e-5, 1e-6)) << w;
  // A Gaussian that covers nothing gets the largest weight.
  EXPECT_EQ(w.argmax().item<int64_t>(), 0);
  // gamma 2 squares the ratios: 1, 1/4, 1/16, 1/4 (mean 25/64).
  const at::Tensor w2 =
      gaussians::inverseContributionWeights(at::tensor({0.0f, 1.0f, 3.0f, 1.0f}), 2.0);
  const float k2 = 64.0f / 25.0f;
  EXPECT_TRUE(at::allclose(w2, at::tensor({k2, k2 / 4, k2 / 16, k2 / 4}), 1e-5, 1e-6)) << w2;
}

TEST(InverseContributionWeights, ZeroExponentOrNoContributionGivesOnes) {
  const at::Tensor c = at::tensor({0.0f, 2.0f, 5.0f});
  EXPECT_TRUE(at::equal(gaussians::inverseContributionWeights(c, 0.0), at::ones({3})));
  EXPECT_TRUE(at::equal(gaussians::inverseContributionWeights(at::zeros({4}), 1.0), at::ones({4})));
  EXPECT_EQ(gaussians::inverseContributionWeights(at::zeros({0}), 1.0).numel(), 0);
  EXPECT_THROW(gaussians::inverseContributionWeights(c, -1.0), Error);
}

TEST(InverseContributionWeights, AZeroMedianFallsBackToTheMeanOfThePositiveOnes) {
  // Median 0; the positive contributions 2 and 4 average 3: 1, 1, 1, 3/5, 3/7 before scaling.
  const at::Tensor w =
      gaussians::inverseContributionWeights(at::tensor({0.0f, 0.0f, 2.0f, 0.0f, 4.0f}), 1.0);
  const at::Tensor raw = at::tensor({1.0f, 1.0f, 0.6f, 1.0f, 3.0f / 7.0f});
  EXPECT_TRUE(at::allclose(w, raw / raw.mean(), 1e-5, 1e-6)) << w;
}

}  // namespace
}  // namespace sadsplat
