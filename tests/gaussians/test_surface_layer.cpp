// The first surface of a map render: against the rasterizer (composited to the end it is the
// rasterizer's blend) and against stacked and tilted Gaussians whose surface is known by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/surface_layer.h"
#include "test_support/photo_camera.h"

namespace sadsplat {
namespace {

using gaussians::GaussianParams;
using gaussians::RasterCamera;
using test::smallPhotoCamera;

// Looking down the world's z axis from z = 0 (identity rotation): camera z = world z; 10
// pixels per unit, the world origin at pixel (32, 32).
RasterCamera mapCamera() {
  RasterCamera c;
  c.orthographic = true;
  c.width = c.height = 64;
  c.fx = c.fy = 10;
  c.cx = c.cy = 32;
  return c;
}

gaussians::RenderSettings flat() {
  gaussians::RenderSettings s;
  s.sh_degree = 0;
  return s;
}

double logit(double p) { return std::log(p / (1 - p)); }

// Flat, round Gaussians (sigma 1 in x and y, 0.01 in z) at (0, 0, z) with the given opacities
// and 2-channel features.
GaussianParams stack(const std::vector<double>& z, const std::vector<double>& opacity,
                     const std::vector<std::array<double, 2>>& feature) {
  const auto n = static_cast<std::int64_t>(z.size());
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  GaussianParams g;
  g.means = at::zeros({n, 3}, opts);
  g.quats = at::zeros({n, 4}, opts);
  g.log_scales = at::zeros({n, 3}, opts);
  g.opacity_logits = at::zeros({n}, opts);
  g.features = at::zeros({n, 2}, opts);
  g.sh = at::zeros({n, 1, 3}, opts);
  for (std::int64_t i = 0; i < n; ++i) {
    g.means[i][2] = z[i];
    g.quats[i][0] = 1;
    g.log_scales[i][2] = std::log(0.01);
    g.opacity_logits[i] = logit(opacity[i]);
    g.features[i][0] = feature[i][0];
    g.features[i][1] = feature[i][1];
  }
  return g;
}

TEST(SurfaceLayer, CompositedToTheEndItIsTheRasterizersBlend) {
  at::manual_seed(7);
  const std::int64_t n = 60;
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  GaussianParams g;
  g.means = at::cat({at::rand({n, 2}, opts) * 5 - 2.5, at::rand({n, 1}, opts) * 4 + 1}, 1);
  g.quats = at::randn({n, 4}, opts);
  g.log_scales = at::log(at::rand({n, 3}, opts) * 0.8 + 0.1);
  g.opacity_logits = at::randn({n}, opts) * 2;
  g.features = at::randn({n, 3}, opts);
  g.sh = at::zeros({n, 1, 3}, opts);
  const RasterCamera cam = mapCamera();
  const gaussians::RenderResult r = gaussians::render(g, cam, flat());
  const gaussians::SurfaceLayer all = gaussians::renderSurfaceLayer(g, cam, 1.0001e-4);
  const at::Tensor alpha = r.alpha.to(at::kFloat);
  EXPECT_LT((all.weight - alpha).abs().max().item<double>(), 1e-6);
  const at::Tensor blended = all.features * all.weight.unsqueeze(2);
  EXPECT_LT((blended - r.features.to(at::kFloat)).abs().max().item<double>(), 1e-5);
  EXPECT_GT(alpha.gt(0.5).sum().item<int>(), 500);  // the scene covers much of the image
}

TEST(SurfaceLayer, AnOpaqueRoofHidesTheGroundBelowIt) {
  // A roof of opacity 0.9 at z = 2 over ground of 0.99 at z = 8: the transmittance falls to 0.1
  // at the roof. The blend's depth lies 0.6 below the roof; the layer's is the roof's.
  GaussianParams g = stack({2, 8}, {0.9, 0.99}, {{{1, 0}}, {{0, 1}}});
  g.log_scales[1][0] = std::log(3.0);  // the ground reaches further
  g.log_scales[1][1] = std::log(3.0);
  const RasterCamera cam = mapCamera();
  const gaussians::SurfaceLayer layer = gaussians::renderSurfaceLayer(g, cam);
  const gaussians::RenderResult r = gaussians::render(g, cam, flat());
  ASSERT_TRUE(layer.reached[32][32].item<bool>());
  EXPECT_NEAR(layer.depth[32][32].item<double>(), 2.0, 1e-6);
  EXPECT_NEAR(layer.features[32][32][0].item<double>(), 1.0, 1e-6);
  EXPECT_NEAR(layer.features[32][32][1].item<double>(), 0.0, 1e-6);
  EXPECT_GT(r.depth[32][32].item<double>(), 2.5);
  // Far from the centre the roof's alpha is small: 2 of its sigmas out (pixel 52) it is 0.11,
  // the ground's (sigma 3) 0.78, and the ground takes the transmittance below 0.5 there.
  EXPECT_TRUE(layer.reached[32][52].item<bool>());
  EXPECT_NEAR(layer.depth[32][52].item<double>(), 8.0, 1e-6);
  EXPECT_GT(layer.features[32][52][1].item<double>(), layer.features[32][52][0].item<double>());
}

TEST(SurfaceLayer, ASheerVeilLetsTheSurfaceBehindItThrough) {
  // A veil of 0.3 over the ground: transmittance ~0.7 after the veil, below 0.5 at the ground.
  // The features are the veil's and the ground's, weighted as composited. Pixel (32, 32)'s
  // centre lies half a pixel from the Gaussians' in x and y; their 2D variance is 100 px^2 +
  // the rasterizer's 0.3 dilation.
  const GaussianParams g = stack({2, 8}, {0.3, 0.99}, {{{1, 0}}, {{0, 1}}});
  const gaussians::SurfaceLayer layer = gaussians::renderSurfaceLayer(g, mapCamera());
  ASSERT_TRUE(layer.reached[32][32].item<bool>());
  EXPECT_NEAR(layer.depth[32][32].item<double>(), 8.0, 1e-6);
  const double G = std::exp(-0.5 * 0.5 / 100.3);
  const double veil = 0.3 * G, ground = (1 - veil) * 0.99 * G;
  EXPECT_NEAR(layer.weight[32][32].item<double>(), veil + ground, 1e-6);  // float output
  EXPECT_NEAR(layer.features[32][32][0].item<double>(), veil / (veil + ground), 1e-6);
  // Off the stack entirely: nothing reached, no weight.
  EXPECT_FALSE(layer.reached[0][0].item<bool>());
  EXPECT_EQ(layer.weight[0][0].item<double>(), 0.0);
}

TEST(SurfaceLayer, ATiltedRoofKeepsItsSlope) {
  // A thin disc at depth 5 tilted 30 degrees about the y axis: its plane is z = 5 + tan(30) x
  // (the disc's normal rotated from z towards -x). One pixel is 0.1 units.
  GaussianParams g = stack({5}, {0.99}, {{{1, 0}}});
  const double half = 15.0 * M_PI / 180;  // quaternion of a 30-degree turn about y
  g.quats[0][0] = std::cos(half);
  g.quats[0][2] = std::sin(half);
  g.log_scales[0][0] = std::log(2.0);
  g.log_scales[0][1] = std::log(2.0);
  const gaussians::SurfaceLayer layer = gaussians::renderSurfaceLayer(g, mapCamera());
  for (int px : {22, 32, 42}) {
    ASSERT_TRUE(layer.reached[32][px].item<bool>()) << px;
    const double x = (px + 0.5 - 32) / 10;
    // The disc's plane through the centre: rotating (1, 0, 0) by +30 degrees about y gives
    // (cos 30, 0, -sin 30), so z = 5 - tan(30) x.
    EXPECT_NEAR(layer.depth[32][px].item<double>(), 5 - std::tan(M_PI / 6) * x, 0.01) << px;
  }
}

// Through a photo's (pinhole) camera: composited to the end it is the rasterizer's blend too,
// and a tilted disc's surface is where each pixel's ray crosses the disc's plane (not the plane
// of constant depth through its centre, nor the orthographic camera's vertical line).
TEST(SurfaceLayer, ThroughAPinholeCameraItFollowsEachRayToTheSurface) {
  RasterCamera pinhole;
  pinhole.width = pinhole.height = 64;
  pinhole.fx = pinhole.fy = 40;
  pinhole.cx = pinhole.cy = 32;
  at::manual_seed(11);
  const std::int64_t n = 40;
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  GaussianParams r;
  r.means = at::cat({at::rand({n, 2}, opts) * 4 - 2, at::rand({n, 1}, opts) * 4 + 3}, 1);
  r.quats = at::randn({n, 4}, opts);
  r.log_scales = at::log(at::rand({n, 3}, opts) * 0.5 + 0.1);
  r.opacity_logits = at::randn({n}, opts) * 2;
  r.features = at::randn({n, 2}, opts);
  r.sh = at::zeros({n, 1, 3}, opts);
  const gaussians::RenderResult blend = gaussians::render(r, pinhole, flat());
  const gaussians::SurfaceLayer all = gaussians::renderSurfaceLayer(r, pinhole, 1.0001e-4);
  EXPECT_LT((all.weight - blend.alpha.to(at::kFloat)).abs().max().item<double>(), 1e-6);

  // The disc of ATiltedRoofKeepsItsSlope, 5 in front of the camera: its plane is
  // z = 5 - tan(30) x; the ray through pixel u is x = z (u + 0.5 - 32) / 40, so it meets the
  // plane at z = 5 / (1 + tan(30) (u + 0.5 - 32) / 40).
  GaussianParams g = stack({5}, {0.99}, {{{1, 0}}});
  const double half = 15.0 * M_PI / 180;
  g.quats[0][0] = std::cos(half);
  g.quats[0][2] = std::sin(half);
  g.log_scales[0][0] = std::log(2.0);
  g.log_scales[0][1] = std::log(2.0);
  const gaussians::SurfaceLayer layer = gaussians::renderSurfaceLayer(g, pinhole);
  for (int px : {22, 32, 42}) {
    ASSERT_TRUE(layer.reached[32][px].item<bool>()) << px;
    const double ray = (px + 0.5 - 32) / 40;
    EXPECT_NEAR(layer.depth[32][px].item<double>(), 5 / (1 + std::tan(M_PI / 6) * ray), 0.01) << px;
  }
}

// Flat Gaussians facing the camera at (x, y, z) triples: scale 0.3 (0.01 in z), opacity 0.8.
GaussianParams flatAt(const std::vector<double>& centres) {
  const auto n = static_cast<std::int64_t>(centres.size() / 3);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  GaussianParams g;
  g.means = at::tensor(centres, opts).view({n, 3});
  g.quats = at::zeros({n, 4}, opts);
  g.quats.select(1, 0).fill_(1);
  g.log_scales = at::full({n, 3}, std::log(0.3), opts);
  g.log_scales.select(1, 2).fill_(std::log(0.01));
  g.opacity_logits = at::full({n}, logit(0.8), opts);
  g.sh = at::zeros({n, 1, 3}, opts);
  return g;
}

double gapOf(const at::Tensor& sums, int i) {
  return sums[i][1].item<double>() / sums[i][0].item<double>();
}

// Alone, a Gaussian makes the surface it is compared with (gap 0), and its weight is summed over
// the pixels where it takes the transmittance below 0.5 only.
TEST(SurfaceGapSums, ASurfaceAloneHasNoGap) {
  const GaussianParams one = flatAt({0.1, 0, 6});
  const at::Tensor sums = gaussians::surfaceGapSums(one, smallPhotoCamera());
  const gaussians::SurfaceLayer layer = gaussians::renderSurfaceLayer(one, smallPhotoCamera());
  ASSERT_GT(sums[0][0].item<double>(), 1);
  EXPECT_NEAR(sums[0][0].item<double>(),
              (layer.weight * layer.reached.to(at::kFloat)).sum().item<double>(), 1e-4);
  EXPECT_NEAR(gapOf(sums, 0), 0.0, 1e-4);
}

// A faint floater in front of a roof keeps its gap (the roof lies 3 behind it where it is seen);
// the middle of a roof made of 5 x 5 semi-transparent Gaussians has none (the median depth is
// the roof's, where the expected depth would blend in the wall behind it); the wall far behind,
// seen only around the roof, is judged there and not where the roof hides it; a Gaussian
// behind the wall and one drawn only where no surface is reached (the wall's faint corner) sum
// to nothing.
TEST(SurfaceGapSums, FloatersKeepTheirGapAndHiddenGaussiansCountNowhere) {
  std::vector<double> centres = {0, 0, 20, 0, 0, 2, 0, 0, 30, -1.55, -1.15, 3};
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) centres.insert(centres.end(), {0.3 * i, 0.3 * j, 5});
  }
  GaussianParams g = flatAt(centres);
  g.log_scales[0][0] = g.log_scales[0][1] = std::log(8.0);  // the wall
  g.opacity_logits[0] = logit(0.99);
  g.opacity_logits[1] = logit(0.2);   // the floater
  g.opacity_logits[3] = logit(0.05);  // faint, small, in the image's corner (pixel 1, 1)
  g.log_scales[3][0] = g.log_scales[3][1] = std::log(0.1);
  g.opacity_logits.narrow(0, 4, 25).fill_(logit(0.3));  // the roof
  const at::Tensor sums = gaussians::surfaceGapSums(g, smallPhotoCamera());
  // The floater: at least the roof 3 behind it (where it overhangs the roof, the wall 18).
  EXPECT_GT(gapOf(sums, 1), 2.5);
  EXPECT_LT(std::abs(gapOf(sums, 4 + 12)), 0.05);  // the roof's middle
  EXPECT_LT(std::abs(gapOf(sums, 0)), 0.5);        // the wall
  EXPECT_EQ(sums[2][0].item<double>(), 0.0);       // behind the wall
  EXPECT_EQ(sums[3][0].item<double>(), 0.0);       // where the wall is too faint to be reached
  // Two cameras: sums add up per camera (SurfaceDepth::kMedianWhereSeen takes |gap| per
  // camera); a camera that does not see a Gaussian adds nothing for it.
  const at::Tensor side = gaussians::surfaceGapSums(g, smallPhotoCamera(40));
  EXPECT_EQ(side[1][0].item<double>(), 0.0);
}

TEST(SurfaceLayer, RefusesWhatItCannotRender) {
  const GaussianParams g = stack({2}, {0.9}, {{{1, 0}}});
  EXPECT_THROW(gaussians::renderSurfaceLayer(g, mapCamera(), 0.0), Error);
  EXPECT_THROW(gaussians::renderSurfaceLayer(g, mapCamera(), 1.0), Error);
  GaussianParams bad = g;
  bad.quats = at::zeros({1, 3}, at::kDouble);
  EXPECT_THROW(gaussians::renderSurfaceLayer(bad, mapCamera()), Error);
}

}  // namespace
}  // namespace sadsplat
