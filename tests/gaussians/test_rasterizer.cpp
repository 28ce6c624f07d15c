// The CPU rasterizer (the reference): closed forms, gradients against central finite
// differences in double precision, culling without NaNs, tiling against a brute-force render.
#include <gtest/gtest.h>

#include <c10/core/GradMode.h>
#include <torch/csrc/autograd/autograd.h>

#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/raster_math.h"
#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace {

using gaussians::GaussianParams;
using gaussians::RasterCamera;
using gaussians::RenderSettings;

// A camera at the origin looking down +z.
RasterCamera frontCamera(int width, int height, double f) {
  RasterCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = f;
  c.cx = width / 2.0;
  c.cy = height / 2.0;
  return c;
}

// n Gaussians in front of `camera`, in double, with C feature channels, seeded.
GaussianParams randomScene(int n, int C, std::uint64_t seed, double spread = 0.35) {
  at::manual_seed(seed);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  GaussianParams g;
  g.means = at::cat({(at::rand({n, 2}, opts) - 0.5) * 2 * spread, 2.5 + at::rand({n, 1}, opts)}, 1);
  g.quats = at::randn({n, 4}, opts);
  g.log_scales = at::log(0.05 + 0.1 * at::rand({n, 3}, opts));
  g.opacity_logits = at::rand({n}, opts) * 2 - 1.5;
  g.sh = at::randn({n, 16, 3}, opts) * 0.1;
  g.features = at::randn({n, C}, opts);
  return g;
}

// A scalar loss touching every output with fixed random weights.
struct WeightedLoss {
  at::Tensor w_rgb, w_feat, w_alpha, w_depth;
  WeightedLoss(int h, int w, int C) {
    at::manual_seed(99);
    const auto opts = at::TensorOptions().dtype(at::kDouble);
    w_rgb = at::randn({h, w, 3}, opts);
    w_feat = at::randn({h, w, C}, opts);
    w_alpha = at::randn({h, w}, opts);
    w_depth = at::randn({h, w}, opts) * 0.1;
  }
  at::Tensor operator()(const gaussians::RenderResult& r) const {
    return (r.rgb * w_rgb).sum() + (r.features * w_feat).sum() + (r.alpha * w_alpha).sum() +
           (r.depth * w_depth).sum();
  }
};

void expectGradientsMatchFiniteDifferences(GaussianParams g, const RasterCamera& cam,
                                           const RenderSettings& settings, double tolerance) {
  at::Tensor GaussianParams::*const members[] = {
      &GaussianParams::means, &GaussianParams::quats,          &GaussianParams::log_scales,
      &GaussianParams::sh,    &GaussianParams::opacity_logits, &GaussianParams::features};
  const char* names[] = {"means", "quats", "log_scales", "sh", "opacity_logits", "features"};
  const WeightedLoss loss(cam.height, cam.width, static_cast<int>(g.features.size(1)));
  std::vector<at::Tensor> tensors;
  for (auto member : members) {
    g.*member = (g.*member).detach().clone().requires_grad_(true);
    tensors.push_back(g.*member);
  }
  const auto grads = torch::autograd::grad({loss(gaussians::render(g, cam, settings))}, tensors);

  const double eps = 1e-6;
  c10::AutoGradMode no_grad(false);
  for (std::size_t k = 0; k < tensors.size(); ++k) {
    const at::Tensor base = tensors[k].detach();
    const at::Tensor analytic = grads[k].reshape({-1});
    for (int64_t i = 0; i < base.numel(); ++i) {
      auto eval = [&](double delta) {
        GaussianParams p = g;
        at::Tensor changed = base.clone();
        changed.view({-1})[i] += delta;
        p.*members[k] = changed;
        return loss(gaussians::render(p, cam, settings)).item<double>();
      };
      const double numeric = (eval(eps) - eval(-eps)) / (2 * eps);
      EXPECT_NEAR(analytic[i].item<double>(), numeric, tolerance * (1.0 + std::abs(numeric)))
          << names[k] << "[" << i << "]";
    }
  }
}

TEST(Rasterizer, SingleIsotropicGaussianMatchesTheClosedForm) {
  const RasterCamera cam = frontCamera(32, 32, 40.0);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const double sigma = 0.1, z = 4.0, opacity = 0.6;
  GaussianParams g;
  g.means = at::tensor({0.0, 0.0, z}, opts).reshape({1, 3});
  g.quats = at::tensor({1.0, 0.0, 0.0, 0.0}, opts).reshape({1, 4});
  g.log_scales = at::full({1, 3}, std::log(sigma), opts);
  g.opacity_logits = at::full({1}, std::log(opacity / (1 - opacity)), opts);
  g.sh = at::zeros({1, 16, 3}, opts);
  g.sh[0][0] = at::tensor({0.5, -0.5, 1.0}, opts) / 0.28209479177387814;  // rgb 1, 0, 1.5
  g.features = at::tensor({2.0, -3.0}, opts).reshape({1, 2});
  RenderSettings settings;
  settings.background = {0.25f, 0.5f, 0.75f};
  const auto r = gaussians::render(g, cam, settings);

  EXPECT_NEAR(r.means2d[0][0].item<double>(), 16.0, 1e-12);
  EXPECT_NEAR(r.means2d[0][1].item<double>(), 16.0, 1e-12);
  const double s2 = std::pow(40.0 * sigma / z, 2) + 0.3;  // EWA + low-pass dilation
  for (auto [px, py] : std::vector<std::pair<int, int>>{{16, 16}, {15, 15}, {18, 16}, {16, 12}}) {
    const double dx = 16.0 - (px + 0.5), dy = 16.0 - (py + 0.5);
    const double alpha = opacity * std::exp(-0.5 * (dx * dx + dy * dy) / s2);
    if (alpha < 1.0 / 255) continue;
    EXPECT_NEAR(r.alpha[py][px].item<double>(), alpha, 1e-12) << px << "," << py;
    EXPECT_NEAR(r.rgb[py][px][0].item<double>(), alpha * 1.0 + (1 - alpha) * 0.25, 1e-12);
    EXPECT_NEAR(r.rgb[py][px][1].item<double>(), (1 - alpha) * 0.5, 1e-12);
    EXPECT_NEAR(r.features[py][px][1].item<double>(), -3.0 * alpha, 1e-12);
    EXPECT_NEAR(r.depth[py][px].item<double>(), z, 1e-12);
  }
  // Far from the centre alpha falls under 1/255: pure background, depth 0.
  EXPECT_EQ(r.alpha[0][0].item<double>(), 0.0);
  EXPECT_NEAR(r.rgb[0][0][2].item<double>(), 0.75, 1e-7);
  EXPECT_EQ(r.depth[0][0].item<double>(), 0.0);
  EXPECT_GT(r.radii[0].item<int>(), 0);
}

TEST(Rasterizer, GradientsOfEveryInputMatchFiniteDifferences) {
  // One 16x16 tile, so no tile-boundary discontinuities; SH degree 3, 3 feature channels.
  const RasterCamera cam = frontCamera(16, 16, 22.0);
  RenderSettings settings;
  settings.background = {0.1f, 0.2f, 0.3f};
  expectGradientsMatchFiniteDifferences(randomScene(5, 3, 1), cam, settings, 1e-5);
}

// Closed gates (RenderSettings::closed_gate_gradients): a Gaussian whose gate is 0 renders
// nothing, and its gate gets the derivative of the render at gate 0. Without depth the loss is
// linear in the pixels, and each pixel is affine in one Gaussian's alpha over the pixels where
// the Gaussian blends (none saturates here, no alpha reaches the 0.99 clamp); opacity x gate 1
// blends at exactly the pixels where the closed gate is counted. So that derivative is
// L(gate 1) - L(gate 0). The render and every other gradient are those without the setting, bit
// for bit; without it a closed gate gets no gradient.
TEST(Rasterizer, AClosedGateGetsTheRendersDerivativeAtZero) {
  const RasterCamera cam = frontCamera(40, 36, 30.0);  // 3 x 3 tiles
  const GaussianParams g = randomScene(8, 3, 21, 0.6);
  const at::Tensor gate = at::tensor({1.0, 0.0, 0.6, 0.0, 1.0, 0.0, 0.3, 1.0}, g.means.options());
  RenderSettings settings;
  settings.depth = false;
  settings.background = {0.1f, 0.2f, 0.3f};
  at::manual_seed(7);
  const at::Tensor w_rgb = at::randn({36, 40, 3}, g.means.options());
  const at::Tensor w_feat = at::randn({36, 40, 3}, g.means.options());
  const at::Tensor w_alpha = at::randn({36, 40}, g.means.options());
  const auto loss = [&](const gaussians::RenderResult& r) {
    return (r.rgb * w_rgb).sum() + (r.features * w_feat).sum() + (r.alpha * w_alpha).sum();
  };
  struct Run {
    gaussians::RenderResult render;
    std::vector<at::Tensor> grads;  // gate, opacity_logits, means, log_scales, sh, features
  };
  const auto run = [&](bool closed_gate_gradients) {
    settings.closed_gate_gradients = closed_gate_gradients;
    GaussianParams p = g;
    std::vector<at::Tensor> inputs;
    for (at::Tensor* t :
         {&p.opacity_gate, &p.opacity_logits, &p.means, &p.log_scales, &p.sh, &p.features}) {
      *t = (t == &p.opacity_gate ? gate : *t).detach().clone().requires_grad_(true);
      inputs.push_back(*t);
    }
    Run out;
    out.render = gaussians::render(p, cam, settings);
    out.grads = torch::autograd::grad({loss(out.render)}, inputs);
    return out;
  };
  const Run with = run(true), without = run(false);
  EXPECT_TRUE(at::equal(with.render.rgb, without.render.rgb));
  EXPECT_TRUE(at::equal(with.render.alpha, without.render.alpha));
  for (std::size_t k = 1; k < with.grads.size(); ++k) {
    EXPECT_TRUE(at::equal(with.grads[k], without.grads[k])) << "gradient " << k;
  }
  c10::AutoGradMode no_grad(false);
  int reached = 0;
  for (int64_t i = 0; i < 8; ++i) {
    if (gate[i].item<double>() != 0) {
      EXPECT_EQ(with.grads[0][i].item<double>(), without.grads[0][i].item<double>()) << i;
      continue;
    }
    EXPECT_EQ(without.grads[0][i].item<double>(), 0.0) << i;
    GaussianParams open = g;
    open.opacity_gate = gate.clone();
    open.opacity_gate[i] = 1.0;
    const double expected = loss(gaussians::render(open, cam, settings)).item<double>() -
                            loss(with.render).item<double>();
    EXPECT_NEAR(with.grads[0][i].item<double>(), expected, 1e-9 * (1 + std::abs(expected))) << i;
    reached += std::abs(expected) > 1e-3;
  }
  EXPECT_EQ(reached, 3) << "every closed gate reaches pixels";
}

TEST(Rasterizer, BlackAndGreyBackgroundsComposeLikeAColouredOne) {
  // Black and grey take their own paths (no colour tensor): the same image as rgb + (1 - alpha)
  // * background, and gradients that match finite differences.
  const RasterCamera cam = frontCamera(16, 16, 22.0);
  const GaussianParams g = randomScene(5, 2, 7);
  RenderSettings black;
  const auto r0 = gaussians::render(g, cam, black);
  RenderSettings grey;
  grey.background = {0.4f, 0.4f, 0.4f};
  const auto r1 = gaussians::render(g, cam, grey);
  const at::Tensor expected = r0.rgb + (1 - r0.alpha).unsqueeze(2) * 0.4f;
  EXPECT_LT((r1.rgb - expected).abs().max().item<double>(), 1e-6);
  EXPECT_GT((r1.rgb - r0.rgb).abs().max().item<double>(), 0.1);  // the grey is there
  EXPECT_TRUE(r0.rgb.is_contiguous());
  expectGradientsMatchFiniteDifferences(g, cam, black, 1e-5);
  expectGradientsMatchFiniteDifferences(g, cam, grey, 1e-5);
}

TEST(Rasterizer, GradientsWithATiltedOffCentreCameraMatchFiniteDifferences) {
  RasterCamera cam = frontCamera(16, 12, 18.0);
  cam.cx = 7.3;
  cam.cy = 6.6;
  cam.fy = 19.5;
  const double angle = 0.2;
  cam.qvec = {std::cos(angle / 2), 0.0, std::sin(angle / 2), 0.0};
  cam.tvec = {0.3, -0.1, 0.2};
  RenderSettings settings;
  settings.sh_degree = 2;
  auto g = randomScene(4, 1, 2, 0.25);
  g.means.select(1, 0).add_(-0.5);  // rotated camera: shift the scene into view
  expectGradientsMatchFiniteDifferences(g, cam, settings, 1e-5);
}

TEST(Rasterizer, GradientsThroughTheFrustumClampMatchFiniteDifferences) {
  // A large Gaussian whose centre lies outside 1.3x the field of view but whose footprint
  // reaches into the image: the clamped Jacobian path of the projection.
  const RasterCamera cam = frontCamera(16, 16, 16.0);
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  GaussianParams g;
  g.means = at::tensor({2.1, 0.1, 3.0}, opts).reshape({1, 3});  // x/z = 0.7 > 1.3 * 0.5
  g.quats = at::tensor({0.9, 0.1, -0.2, 0.3}, opts).reshape({1, 4});
  g.log_scales = at::tensor({std::log(0.9), std::log(0.7), std::log(0.8)}, opts).reshape({1, 3});
  g.opacity_logits = at::full({1}, 0.2, opts);
  g.sh = at::randn({1, 1, 3}, opts) * 0.1;
  g.features = at::randn({1, 2}, opts);
  RenderSettings settings;
  settings.sh_degree = 0;
  const auto r = gaussians::render(g, cam, settings);
  ASSERT_GT(r.radii[0].item<int>(), 0);
  ASSERT_GT(r.alpha.max().item<double>(), 0.01);
  expectGradientsMatchFiniteDifferences(g, cam, settings, 1e-5);
}

// An orthographic camera projects affinely, so the 2D covariance of a rotated, anisotropic
// Gaussian is exactly f^2 times the top-left 2x2 block of R S R^T (+ the dilation), whatever its
// depth: the same Gaussian at z = 3 and at z = 300 renders the same pixels.
TEST(Rasterizer, OrthographicCameraProjectsTheCovarianceExactly) {
  RasterCamera cam = frontCamera(48, 40, 0);
  cam.orthographic = true;
  cam.fx = 30.0;  // pixels per world unit
  cam.fy = 27.0;
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const double opacity = 0.8;
  const double q[4] = {0.9, 0.2, -0.3, 0.25};
  const double sx = 0.12, sy = 0.05, sz = 0.3;
  GaussianParams g;
  g.means = at::tensor({0.1, -0.05, 3.0}, opts).reshape({1, 3});
  g.quats = at::tensor({q[0], q[1], q[2], q[3]}, opts).reshape({1, 4});
  g.log_scales = at::tensor({std::log(sx), std::log(sy), std::log(sz)}, opts).reshape({1, 3});
  g.opacity_logits = at::full({1}, std::log(opacity / (1 - opacity)), opts);
  g.sh = at::zeros({1, 16, 3}, opts);
  g.features = at::ones({1, 1}, opts);
  const auto near = gaussians::render(g, cam);
  g.means[0][2] = 300.0;
  const auto far = gaussians::render(g, cam);
  EXPECT_EQ((near.alpha - far.alpha).abs().max().item<double>(), 0.0);
  EXPECT_NEAR(far.depth[20][27].item<double>(), 300.0, 1e-9);

  // The expected covariance, written out independently of raster_math.h.
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  const double s2[3] = {sx * sx, sy * sy, sz * sz};
  double S[2][2] = {{0, 0}, {0, 0}};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 3; ++k) S[i][j] += R[i][k] * s2[k] * R[j][k];
  const double a = cam.fx * cam.fx * S[0][0] + 0.3, b = cam.fx * cam.fy * S[0][1],
               c = cam.fy * cam.fy * S[1][1] + 0.3;
  const double det = a * c - b * b;
  const double mx = cam.fx * 0.1 + cam.cx, my = cam.fy * -0.05 + cam.cy;
  EXPECT_NEAR(near.means2d[0][0].item<double>(), mx, 1e-12);
  EXPECT_NEAR(near.means2d[0][1].item<double>(), my, 1e-12);
  int checked = 0;
  for (int py = 0; py < cam.height; ++py) {
    for (int px = 0; px < cam.width; ++px) {
      const double dx = mx - (px + 0.5), dy = my - (py + 0.5);
      const double power = -0.5 * (c * dx * dx - 2 * b * dx * dy + a * dy * dy) / det;
      const double alpha = std::min(0.99, opacity * std::exp(power));
      if (alpha < 1.5 / 255) continue;
      ASSERT_NEAR(near.alpha[py][px].item<double>(), alpha, 1e-12) << px << "," << py;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

TEST(Rasterizer, OrthographicGradientsMatchFiniteDifferences) {
  RasterCamera cam = frontCamera(16, 14, 0);
  cam.orthographic = true;
  cam.fx = 21.0;
  cam.fy = 19.0;
  cam.cx = 7.6;
  const double angle = 0.3;
  cam.qvec = {std::cos(angle / 2), std::sin(angle / 2), 0.0, 0.0};
  cam.tvec = {0.1, 0.2, 0.4};
  RenderSettings settings;
  settings.sh_degree = 3;
  settings.background = {0.2f, 0.1f, 0.0f};
  auto g = randomScene(4, 2, 3, 0.25);
  expectGradientsMatchFiniteDifferences(g, cam, settings, 1e-5);
}

// Gaussians behind an orthographic camera (z below the near plane) are culled; nothing is
// divided by their depth.
TEST(Rasterizer, OrthographicCameraCullsBehindItself) {
  RasterCamera cam = frontCamera(16, 16, 0);
  cam.orthographic = true;
  cam.fx = cam.fy = 10.0;
  auto g = randomScene(6, 1, 4);
  g.means.select(1, 2).fill_(-1.0);
  const auto r = gaussians::render(g, cam);
  EXPECT_EQ((r.radii > 0).sum().item<int64_t>(), 0);
  EXPECT_EQ(r.alpha.abs().max().item<double>(), 0.0);
}

// setRotation inverts the quaternion -> matrix map (up to the quaternion's sign), in every
// branch of Shepperd's method (w, x, y or z the largest component).
TEST(Rasterizer, CameraRotationFromAMatrixRoundTrips) {
  const double qs[][4] = {{0.9, 0.1, -0.2, 0.3},
                          {0.1, 0.9, 0.2, -0.3},
                          {0.05, -0.2, 0.95, 0.1},
                          {-0.1, 0.2, 0.1, 0.96},
                          {0.0, 0.0, 0.0, 1.0}};
  for (const auto& q0 : qs) {
    const double n = std::sqrt(q0[0] * q0[0] + q0[1] * q0[1] + q0[2] * q0[2] + q0[3] * q0[3]);
    const double q[4] = {q0[0] / n, q0[1] / n, q0[2] / n, q0[3] / n};
    double R[9];
    gaussians::raster::quatToRotation(q, R);
    RasterCamera cam;
    std::array<double, 9> Ra;
    for (int i = 0; i < 9; ++i) Ra[i] = R[i];
    cam.setRotation(Ra);
    const double sign =
        (cam.qvec[0] * q[0] + cam.qvec[1] * q[1] + cam.qvec[2] * q[2] + cam.qvec[3] * q[3]) < 0
            ? -1.0
            : 1.0;
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(sign * cam.qvec[k], q[k], 1e-12) << k;
  }
}

TEST(Rasterizer, CulledAndDegenerateGaussiansGiveZerosNotNaNs) {
  const RasterCamera cam = frontCamera(20, 20, 20.0);
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  GaussianParams g;
  g.means = at::tensor({0.0f, 0.0f, -3.0f,   // behind the camera
                        0.0f, 0.0f, 0.001f,  // in front of the near plane
                        500.0f, 0.0f, 3.0f,  // far off-screen
                        0.0f, 0.0f, 3.0f,    // zero quaternion
                        0.1f, 0.0f, 3.0f,    // infinite scale
                        0.0f, 0.1f, 3.0f},   // vanishing scale: only the dilation is left
                       opts)
                .reshape({6, 3});
  g.quats = at::tensor({1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f,
                        0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f},
                       opts)
                .reshape({6, 4});
  g.log_scales = at::full({6, 3}, -2.0f, opts);
  g.log_scales[4].fill_(1000.0f);
  g.log_scales[5].fill_(-100.0f);
  g.opacity_logits = at::zeros({6}, opts);
  g.sh = at::zeros({6, 16, 3}, opts);
  g.features = at::ones({6, 2}, opts);
  for (at::Tensor* t : {&g.means, &g.quats, &g.log_scales, &g.opacity_logits, &g.sh, &g.features}) {
    t->requires_grad_(true);
  }
  const auto r = gaussians::render(g, cam);
  const auto radii = r.radii;
  EXPECT_EQ(radii[0].item<int>(), 0);
  EXPECT_EQ(radii[1].item<int>(), 0);
  EXPECT_EQ(radii[2].item<int>(), 0);
  EXPECT_EQ(radii[3].item<int>(), 0);
  EXPECT_EQ(radii[4].item<int>(), 0);
  EXPECT_GT(radii[5].item<int>(), 0);
  (r.rgb.sum() + r.features.sum() + r.alpha.sum() + r.depth.sum()).backward();
  for (const at::Tensor* t : {&r.rgb, &r.features, &r.alpha, &r.depth}) {
    EXPECT_TRUE(at::isfinite(*t).all().item<bool>());
  }
  for (at::Tensor* t : {&g.means, &g.quats, &g.log_scales, &g.opacity_logits, &g.features}) {
    EXPECT_TRUE(at::isfinite(t->grad()).all().item<bool>());
    for (int i = 0; i < 5; ++i) EXPECT_EQ(t->grad()[i].abs().sum().item<float>(), 0.f) << i;
  }
}

TEST(Rasterizer, EmptySceneRendersTheBackground) {
  const RasterCamera cam = frontCamera(17, 9, 10.0);
  GaussianParams g;
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  g.means = at::zeros({0, 3}, opts);
  g.quats = at::zeros({0, 4}, opts);
  g.log_scales = at::zeros({0, 3}, opts);
  g.opacity_logits = at::zeros({0}, opts);
  g.sh = at::zeros({0, 16, 3}, opts);
  g.features = at::zeros({0, 4}, opts);
  RenderSettings settings;
  settings.background = {0.2f, 0.4f, 0.6f};
  const auto r = gaussians::render(g, cam, settings);
  ASSERT_EQ(r.rgb.sizes(), (std::vector<int64_t>{9, 17, 3}));
  EXPECT_TRUE(at::allclose(r.rgb.select(2, 1), at::full({9, 17}, 0.4f, opts)));
  EXPECT_EQ(r.features.sizes(), (std::vector<int64_t>{9, 17, 4}));
  EXPECT_EQ(r.alpha.abs().sum().item<float>(), 0.f);
  EXPECT_EQ(r.depth.abs().sum().item<float>(), 0.f);
}

TEST(Rasterizer, TiledRenderEqualsABruteForceComposite) {
  // 40 Gaussians over a 45x35 image (3x3 tiles): compare with compositing every Gaussian at
  // every pixel in global depth order, using the projection outputs.
  const RasterCamera cam = frontCamera(45, 35, 30.0);
  auto g = randomScene(40, 2, 5, 0.8);
  const auto proj = gaussians::projectGaussians(g.means, g.quats, g.log_scales, cam);
  const at::Tensor values =
      at::cat({at::rand({40, 3}, g.means.options()), g.features, proj[2].unsqueeze(1)}, 1);
  const at::Tensor opac = at::sigmoid(g.opacity_logits);
  const auto out =
      gaussians::rasterizeToPixels(proj[0], proj[1], opac, values, proj[3], proj[2], 45, 35);
  const at::Tensor order = std::get<1>(proj[2].sort(/*stable=*/true, 0, false));
  const auto m2 = proj[0].accessor<double, 2>();
  const auto co = proj[1].accessor<double, 2>();
  const auto radii = proj[3].accessor<int, 1>();
  const auto op = opac.accessor<double, 1>();
  const auto val = values.accessor<double, 2>();
  const auto ord = order.accessor<int64_t, 1>();
  const auto img = out[0].accessor<double, 3>();
  double worst = 0;
  for (int py = 0; py < 35; ++py) {
    for (int px = 0; px < 45; ++px) {
      std::vector<double> acc(6, 0.0);
      double T = 1;
      for (int k = 0; k < 40; ++k) {
        const int64_t i = ord[k];
        if (radii[i] == 0) continue;
        // Only Gaussians whose 3-sigma box touches this pixel's tile take part, as in the
        // reference rasterizer; far pixels get alpha < 1/255 anyway.
        const double dx = m2[i][0] - (px + 0.5), dy = m2[i][1] - (py + 0.5);
        const double power = -0.5 * (co[i][0] * dx * dx + co[i][2] * dy * dy) - co[i][1] * dx * dy;
        if (power > 0) continue;
        const int tx = px / 16, ty = py / 16;
        const int x0 = std::max(0, int(std::floor((m2[i][0] - radii[i]) / 16)));
        const int x1 = int(std::floor((m2[i][0] + radii[i]) / 16));
        const int y0 = std::max(0, int(std::floor((m2[i][1] - radii[i]) / 16)));
        const int y1 = int(std::floor((m2[i][1] + radii[i]) / 16));
        if (tx < x0 || tx > x1 || ty < y0 || ty > y1) continue;
        const double alpha = std::min(0.99, op[i] * std::exp(power));
        if (alpha < 1.0 / 255) continue;
        if (T * (1 - alpha) < 1e-4) break;
        for (int ch = 0; ch < 6; ++ch) acc[ch] += val[i][ch] * alpha * T;
        T *= 1 - alpha;
      }
      for (int ch = 0; ch < 6; ++ch) worst = std::max(worst, std::abs(acc[ch] - img[py][px][ch]));
    }
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(out[1].max().item<double>(), 0.5);  // the scene does cover the image
}

// 80x60 pixels, focal length 60, at the origin looking along +z: the binning tests' camera.
gaussians::raster::Camera<double> binningTestCamera() {
  gaussians::raster::Camera<double> cam{};
  cam.R[0] = cam.R[4] = cam.R[8] = 1;
  cam.fx = cam.fy = 60;
  cam.cx = 40;
  cam.cy = 30;
  cam.width = 80;
  cam.height = 60;
  cam.near_plane = 0.01;
  return cam;
}

// A random Gaussian in front of binningTestCamera(), projected into *p; odd k gives a needle (one
// scale 10-40x the others). False when it does not project.
bool randomBinningGaussian(std::mt19937& rng, int k, gaussians::raster::Projected<double>* p) {
  std::uniform_real_distribution<double> u(-1, 1);
  const double mean[3] = {0.3 * u(rng), 0.3 * u(rng), 2.5 + u(rng)};
  const double quat[4] = {u(rng), u(rng), u(rng), u(rng)};
  const double stretch = k % 2 ? 10 + 30 * (1 + u(rng)) / 2 : 1;
  const double log_scale[3] = {std::log((0.005 + 0.02 * (1 + u(rng))) * stretch),
                               std::log(0.005 + 0.02 * (1 + u(rng))),
                               std::log(0.005 + 0.02 * (1 + u(rng)))};
  return gaussians::raster::projectGaussian(mean, quat, log_scale, binningTestCamera(), p);
}

// |offset| (x, y) from the projected mean of every pixel centre around it (the 3-sigma box and 2
// pixels more) where pixelAlpha is non-zero, cut at the 3-sigma box: past it an opaque Gaussian
// can still reach 1/255 (out to ~3.3 sigma), and the rasterizer cuts it there by design (as the
// reference 3DGS rasterizer does).
std::vector<std::pair<double, double>> reachablePixelOffsets(
    const gaussians::raster::Projected<double>& p, double opacity) {
  std::vector<std::pair<double, double>> offsets;
  for (int py = -p.radius - 2; py <= p.radius + 2; ++py) {
    for (int px = -p.radius - 2; px <= p.radius + 2; ++px) {
      const double x = std::floor(p.mean2d[0]) + px + 0.5, y = std::floor(p.mean2d[1]) + py + 0.5;
      double G = 0;
      bool clamped = false;
      if (gaussians::raster::pixelAlpha(p.mean2d, p.conic, opacity, x, y, &G, &clamped) == 0) {
        continue;
      }
      const double dx = std::abs(x - p.mean2d[0]), dy = std::abs(y - p.mean2d[1]);
      if (dx <= p.radius && dy <= p.radius) offsets.emplace_back(dx, dy);
    }
  }
  return offsets;
}

TEST(Rasterizer, AlphaExtentHoldsEveryPixelAGaussianCanReach) {
  // The binning radius: every pixel centre of the 3-sigma box where pixelAlpha is non-zero lies
  // inside the box of half-width alphaExtent; faint Gaussians get less than their 3-sigma radius,
  // Gaussians that cannot reach 1/255 get none, opaque ones keep the 3-sigma radius.
  using gaussians::raster::alphaExtent;
  const gaussians::raster::Camera<double> cam = binningTestCamera();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int shrunk = 0, checked = 0;
  for (int k = 0; k < 60; ++k) {
    const double mean[3] = {0.3 * u(rng), 0.3 * u(rng), 2.5 + u(rng)};
    const double quat[4] = {u(rng), u(rng), u(rng), u(rng)};
    const double log_scale[3] = {std::log(0.02 + 0.06 * (1 + u(rng))),
                                 std::log(0.02 + 0.06 * (1 + u(rng))),
                                 std::log(0.02 + 0.06 * (1 + u(rng)))};
    gaussians::raster::Projected<double> p;
    ASSERT_TRUE(gaussians::raster::projectGaussian(mean, quat, log_scale, cam, &p));
    for (double opacity : {1.0 / 300, 1.0 / 255, 0.0045, 0.01, 0.1, 0.5, 0.99, 1.0}) {
      const int extent = alphaExtent(p.radius, opacity);
      EXPECT_LE(extent, p.radius);
      if (opacity >= 0.99) {
        EXPECT_EQ(extent, p.radius);
      }
      if (opacity < 1.0 / 255) {
        EXPECT_EQ(extent, 0);
      }
      shrunk += extent < p.radius;
      for (const auto& [dx, dy] : reachablePixelOffsets(p, opacity)) {
        ++checked;
        EXPECT_LE(dx, extent) << "Gaussian " << k << " opacity " << opacity;
        EXPECT_LE(dy, extent) << "Gaussian " << k << " opacity " << opacity;
      }
    }
  }
  EXPECT_GT(checked, 10000);
  EXPECT_GT(shrunk, 200);  // 1/300 ... 0.01 shrink the box of every Gaussian (4 x 60)
  EXPECT_EQ(alphaExtent(10, std::nan("")), 0);
  EXPECT_EQ(alphaExtent(0, 1.0), 0);
}

TEST(Rasterizer, AlphaBoxHoldsEveryPixelAGaussianCanReachAndCutsElongatedOnes) {
  // The binning box: every pixel centre of the 3-sigma square where pixelAlpha is non-zero lies
  // inside the box of half-widths alphaBox; it is never wider than alphaExtent, and for a
  // Gaussian stretched along one screen axis it is much narrower across that axis.
  using gaussians::raster::alphaBox;
  using gaussians::raster::alphaExtent;
  std::mt19937 rng(11);
  int narrower = 0, checked = 0, boxes = 0;
  for (int k = 0; k < 80; ++k) {
    gaussians::raster::Projected<double> p;
    if (!randomBinningGaussian(rng, k, &p)) continue;
    for (double opacity : {1.0 / 300, 1.0 / 255, 0.0045, 0.05, 0.5, 0.99, 1.0}) {
      const int extent = alphaExtent(p.radius, opacity);
      int rx = -1, ry = -1;
      alphaBox(p.radius, opacity, p.conic, &rx, &ry);
      EXPECT_LE(rx, extent);
      EXPECT_LE(ry, extent);
      EXPECT_EQ(rx <= 0, extent <= 0);
      if (extent > 0) {
        ++boxes;
        narrower += rx * ry * 2 <= extent * extent;
      }
      for (const auto& [dx, dy] : reachablePixelOffsets(p, opacity)) {
        ++checked;
        EXPECT_LE(dx, rx) << "Gaussian " << k << " opacity " << opacity;
        EXPECT_LE(dy, ry) << "Gaussian " << k << " opacity " << opacity;
      }
    }
  }
  EXPECT_GT(checked, 5000);
  // Needles that lie across the screen's axes get at most half the square's area.
  EXPECT_GT(narrower, boxes / 5) << narrower << " of " << boxes;
}

// The box from the alpha ellipse (what the binning takes: one log of the opacity) is
// alphaBox's, bit for bit, in float and double, for every opacity with a box, degenerate conics
// and zero radii included.
template <typename T>
void expectEllipseBoxesEqualAlphaBoxes() {
  using gaussians::raster::alphaBox;
  using gaussians::raster::AlphaEllipse;
  using gaussians::raster::alphaEllipse;
  std::mt19937 rng(12);
  int compared = 0, cut = 0;
  for (int k = 0; k < 200; ++k) {
    gaussians::raster::Projected<double> p;
    if (!randomBinningGaussian(rng, k, &p)) continue;
    const T mean[2] = {T(p.mean2d[0]), T(p.mean2d[1])};
    T conic[3] = {T(p.conic[0]), T(p.conic[1]), T(p.conic[2])};
    if (k % 17 == 0) conic[1] = std::sqrt(conic[0] * conic[2]) * T(1.5);  // not positive definite
    for (double o : {1.0 / 300, 1.0 / 255, 0.0045, 0.02, 0.3, 0.99, 1.0}) {
      for (int radius : {0, p.radius, 3 * p.radius + 1}) {
        const T opacity = T(o);
        int rx = -1, ry = -1;
        alphaBox(radius, opacity, conic, &rx, &ry);
        AlphaEllipse<T> e;
        if (!alphaEllipse(mean, conic, opacity, &e)) {
          EXPECT_EQ(rx, 0) << k << " " << o;
          continue;
        }
        int ex = -1, ey = -1;
        alphaBox(radius, e, &ex, &ey);
        EXPECT_EQ(ex, rx) << k << " " << o << " " << radius;
        EXPECT_EQ(ey, ry) << k << " " << o << " " << radius;
        ++compared;
        cut += rx > 0 && (rx < radius || ry < radius);
      }
    }
  }
  EXPECT_GT(compared, 1500);
  EXPECT_GT(cut, 300) << "boxes cut below the radius are in the test";
}

TEST(Rasterizer, AlphaBoxFromTheEllipseIsAlphaBox) {
  expectEllipseBoxesEqualAlphaBoxes<float>();
  expectEllipseBoxesEqualAlphaBoxes<double>();
}

TEST(Rasterizer, AlphaEllipseMeetsEveryWarpRectangleAGaussianReaches) {
  // The CUDA kernels skip a Gaussian for a warp's 16 x 2 pixels when alphaEllipseMeetsRect says
  // no (the binning's warp masks): in float, as the kernels run it, no pixel centre of a skipped
  // rectangle may have a non-zero pixelAlpha; and the test must skip rectangles (it is not
  // "always yes"), more of them than the ellipse's box would.
  using gaussians::raster::alphaEllipseMeetsRect;
  std::mt19937 rng(23);
  int reached = 0, skipped = 0, skipped_rows = 0, boxed_in = 0;
  for (int k = 0; k < 80; ++k) {
    gaussians::raster::Projected<double> p;
    if (!randomBinningGaussian(rng, k, &p)) continue;
    const float m[2] = {float(p.mean2d[0]), float(p.mean2d[1])};
    const float conic[3] = {float(p.conic[0]), float(p.conic[1]), float(p.conic[2])};
    for (float opacity : {1.f / 300, 1.f / 255, 0.0045f, 0.05f, 0.5f, 1.f}) {
      gaussians::raster::AlphaEllipse<float> e;
      const bool can_reach = gaussians::raster::alphaEllipse(m, conic, opacity, &e);
      float sx = 0.f, sy = 0.f;
      gaussians::raster::alphaEllipseHalfWidths(opacity, conic, &sx, &sy);
      // Rectangles of 16 x 2 pixel centres on a grid around the mean, out to 1.5 radii.
      const int reach = p.radius * 3 / 2 + 16;
      for (int y0 = int(m[1]) - reach; y0 <= int(m[1]) + reach; y0 += 2) {
        for (int x0 = int(m[0]) - reach; x0 <= int(m[0]) + reach; x0 += 16) {
          bool any = false;
          for (int y = y0; y < y0 + 2 && !any; ++y) {
            for (int x = x0; x < x0 + 16 && !any; ++x) {
              float G = 0.f;
              bool clamped = false;
              any = gaussians::raster::pixelAlpha(m, conic, opacity, x + 0.5f, y + 0.5f, &G,
                                                  &clamped) != 0.f;
            }
          }
          const bool meets =
              can_reach && alphaEllipseMeetsRect(e, x0 + 0.5f, y0 + 0.5f, x0 + 15.5f, y0 + 1.5f);
          // What the CUDA warp masks test: the rows the ellipse reaches within the columns.
          float rows0 = 0.f, rows1 = 0.f;
          const bool band = can_reach && gaussians::raster::alphaEllipseRows(
                                             e, x0 + 0.5f, x0 + 15.5f, &rows0, &rows1);
          const bool in_rows = band && y0 + 1.5f >= rows0 && y0 + 0.5f <= rows1;
          if (any) {
            ++reached;
            EXPECT_TRUE(meets) << "Gaussian " << k << " opacity " << opacity << " at " << x0 << ", "
                               << y0;
            EXPECT_TRUE(in_rows) << "Gaussian " << k << " opacity " << opacity << " at " << x0
                                 << ", " << y0 << ": rows " << rows0 << " .. " << rows1;
          }
          skipped += !meets;
          skipped_rows += !in_rows;
          EXPECT_TRUE(in_rows || !meets) << "the row range is the exact band's";
          // In the ellipse's box (what the kernels tested before) but not met.
          const float dx = std::max({x0 + 0.5f - m[0], m[0] - (x0 + 15.5f), 0.f});
          const float dy = std::max({y0 + 0.5f - m[1], m[1] - (y0 + 1.5f), 0.f});
          boxed_in += can_reach && !meets && dx <= sx && dy <= sy;
        }
      }
    }
  }
  EXPECT_GT(reached, 2000);
  EXPECT_GT(skipped, 2000);
  EXPECT_GT(boxed_in, 500) << "the exact test skips no more than the box";
  EXPECT_GT(skipped_rows, skipped * 9 / 10);
}

TEST(Rasterizer, AlphaEllipseMeetsEveryTileAGaussianReachesAndSkipsMostOfANeedlesBox) {
  // The binning's exact tile test: in float, as the kernels run it, every 16 x 16 tile inside the
  // alphaBox with a pixel centre where pixelAlpha is non-zero must pass alphaEllipseMeetsTile; and
  // the test must drop tiles of the box that nothing reaches (a needle across the screen's axes
  // leaves most of its box empty).
  using gaussians::raster::alphaEllipseMeetsTile;
  std::mt19937 rng(29);
  int reached = 0, skipped = 0, boxed = 0;
  for (int k = 0; k < 120; ++k) {
    gaussians::raster::Projected<double> p;
    if (!randomBinningGaussian(rng, k, &p)) continue;
    const float m[2] = {float(p.mean2d[0]) * 3.f, float(p.mean2d[1]) * 3.f};  // across more tiles
    const float conic[3] = {float(p.conic[0]) / 9.f, float(p.conic[1]) / 9.f,
                            float(p.conic[2]) / 9.f};  // the same Gaussian 3x larger on screen
    for (float opacity : {1.f / 300, 1.f / 255, 0.0045f, 0.05f, 0.5f, 1.f}) {
      int rx = 0, ry = 0;
      gaussians::raster::alphaBox(3 * p.radius, opacity, conic, &rx, &ry);
      gaussians::raster::AlphaEllipse<float> e;
      const bool any_reach = gaussians::raster::alphaEllipse(m, conic, opacity, &e);
      if (rx <= 0) continue;
      ASSERT_TRUE(any_reach);
      int x0, y0, x1, y1;
      gaussians::raster::tileRect(m, rx, ry, 1000, 1000, &x0, &y0, &x1, &y1);
      for (int ty = y0; ty < y1; ++ty) {
        for (int tx = x0; tx < x1; ++tx) {
          ++boxed;
          bool any = false;
          for (int y = 16 * ty; y < 16 * ty + 16 && !any; ++y) {
            for (int x = 16 * tx; x < 16 * tx + 16 && !any; ++x) {
              float G = 0.f;
              bool clamped = false;
              any = gaussians::raster::pixelAlpha(m, conic, opacity, x + 0.5f, y + 0.5f, &G,
                                                  &clamped) != 0.f;
            }
          }
          const bool meets = alphaEllipseMeetsTile(e, tx, ty);
          if (any) {
            ++reached;
            EXPECT_TRUE(meets) << "Gaussian " << k << " opacity " << opacity << " tile " << tx
                               << ", " << ty;
          }
          skipped += !meets;
        }
      }
    }
  }
  EXPECT_GT(reached, 1000);
  EXPECT_GT(skipped, boxed / 10) << skipped << " of " << boxed;
  // A degenerate conic has no bound; a Gaussian too faint for any pixel has no ellipse.
  gaussians::raster::AlphaEllipse<float> e;
  const float m[2] = {8.f, 8.f}, flat[3] = {1.f, 1.f, 1.f}, round[3] = {0.1f, 0.f, 0.1f};
  ASSERT_TRUE(gaussians::raster::alphaEllipse(m, flat, 1.f, &e));
  EXPECT_TRUE(alphaEllipseMeetsTile(e, 40, 40));
  EXPECT_FALSE(gaussians::raster::alphaEllipse(m, round, 1.f / 300, &e));
  ASSERT_TRUE(gaussians::raster::alphaEllipse(m, round, 1.f, &e));
  EXPECT_TRUE(alphaEllipseMeetsTile(e, 0, 0));   // holds the mean
  EXPECT_FALSE(alphaEllipseMeetsTile(e, 3, 3));  // ~60 px away, radius ~10 px
}

// Without features and depth (what training renders for a view with no semantic loss) the colour,
// alpha and every colour gradient are those of the full render; features get no gradient.
TEST(Rasterizer, RenderWithoutFeaturesOrDepthGivesTheSameColourAndGradients) {
  const RasterCamera cam = frontCamera(40, 30, 36.0);
  GaussianParams g = randomScene(30, 5, 17);
  for (at::Tensor* t : {&g.means, &g.sh, &g.opacity_logits, &g.features}) {
    *t = t->detach().requires_grad_(true);
  }
  RenderSettings lean;
  lean.features = false;
  lean.depth = false;
  const auto full = gaussians::render(g, cam);
  const auto slim = gaussians::render(g, cam, lean);
  EXPECT_FALSE(slim.depth.defined());
  EXPECT_EQ(slim.features.size(2), 0);
  EXPECT_TRUE(at::allclose(full.rgb, slim.rgb, 1e-12, 1e-12));
  EXPECT_TRUE(at::allclose(full.alpha, slim.alpha, 1e-12, 1e-12));
  const auto a = torch::autograd::grad({(full.rgb * full.rgb).sum()},
                                       {g.means, g.sh, g.opacity_logits}, {}, false, false, true);
  const auto b =
      torch::autograd::grad({(slim.rgb * slim.rgb).sum()},
                            {g.means, g.sh, g.opacity_logits, g.features}, {}, false, false, true);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(at::allclose(a[k], b[k], 1e-10, 1e-12)) << k;
  EXPECT_FALSE(b[3].defined()) << "features were not rendered";
}

// The SH coefficients in two parts (the trainer's sh_dc and sh_rest, read in place) render the
// same colours as one [N, K, 3] tensor, bit for bit, and each part's gradient is its slice of
// the whole's; a part whose rows lie apart (a narrow view) reads the same; coefficients above
// the degree get 0.
TEST(Rasterizer, ShInTwoPartsRendersAndDifferentiatesAsOneTensor) {
  const RasterCamera cam = frontCamera(40, 30, 36.0);
  const std::array<double, 3> centre = cam.centre();
  for (const int degree : {0, 1, 3}) {
    GaussianParams whole = randomScene(30, 0, 23 + degree);
    whole.sh = (at::randn({30, 16, 3}, whole.means.options()) * 0.5).requires_grad_(true);
    GaussianParams parts = whole;
    parts.sh = whole.sh.detach().narrow(1, 0, 1).clone().requires_grad_(true);
    // The rest as a view with rows 48 floats apart, as the narrow of a wider tensor.
    const at::Tensor wide = whole.sh.detach().clone();
    const at::Tensor rest_view = wide.narrow(1, 1, 15);
    ASSERT_FALSE(rest_view.is_contiguous());
    parts.sh_rest = rest_view.detach().requires_grad_(true);
    RenderSettings settings;
    settings.sh_degree = degree;
    const auto a = gaussians::render(whole, cam, settings);
    const auto b = gaussians::render(parts, cam, settings);
    EXPECT_TRUE(at::equal(a.rgb, b.rgb)) << "degree " << degree;
    const at::Tensor w = at::randn_like(a.rgb);
    const auto ga = torch::autograd::grad({(a.rgb * w).sum()}, {whole.sh});
    const auto gb = torch::autograd::grad({(b.rgb * w).sum()}, {parts.sh, parts.sh_rest});
    EXPECT_TRUE(at::equal(gb[0], ga[0].narrow(1, 0, 1))) << "degree " << degree;
    EXPECT_TRUE(at::equal(gb[1], ga[0].narrow(1, 1, 15))) << "degree " << degree;
    const int used = (degree + 1) * (degree + 1);
    EXPECT_GT(ga[0].narrow(1, 0, used).abs().max().item<double>(), 0.0);
    if (used < 16) {
      EXPECT_EQ(gb[1].narrow(1, used - 1, 16 - used).abs().max().item<double>(), 0.0);
    }
    // The colours of evaluateSh agree with the render's inputs too: two parts, one tensor.
    EXPECT_TRUE(
        at::equal(gaussians::evaluateSh(whole.sh, whole.means, centre, degree),
                  gaussians::evaluateSh(parts.sh, parts.sh_rest, parts.means, centre, degree)));
  }
  // Degree 0 from one coefficient: an empty rest.
  GaussianParams one = randomScene(5, 0, 3);
  one.sh = at::randn({5, 1, 3}, one.means.options());
  one.sh_rest = at::zeros({5, 0, 3}, one.means.options());
  RenderSettings flat;
  flat.sh_degree = 0;
  EXPECT_TRUE(at::isfinite(gaussians::render(one, cam, flat).rgb).all().item<bool>());
}

TEST(Rasterizer, ScreenSpaceGradientReachesMeans2d) {
  const RasterCamera cam = frontCamera(32, 32, 30.0);
  auto g = randomScene(10, 0, 8);
  g.means.requires_grad_(true);
  const auto r = gaussians::render(g, cam);
  r.means2d.retain_grad();
  r.rgb.sum().backward();
  ASSERT_TRUE(r.means2d.grad().defined());
  const at::Tensor visible = r.radii > 0;
  EXPECT_GT(visible.sum().item<int64_t>(), 5);
  EXPECT_GT(r.means2d.grad().index({visible}).abs().sum().item<double>(), 0.0);
}

// A render's graph is freed once its outputs are gone: no output may be kept alive by the
// autograd context that its own grad_fn owns (a reference cycle leaked every training step's
// graph, ~8 MB per 800x450 render, until the GPU ran out of memory).
TEST(Rasterizer, RenderGraphIsFreedWithItsOutputs) {
  const RasterCamera cam = frontCamera(32, 32, 30.0);
  auto g = randomScene(10, 0, 8);
  g.means.requires_grad_(true);
  c10::weak_intrusive_ptr<c10::TensorImpl, c10::UndefinedTensorImpl> alpha{
      c10::intrusive_ptr<c10::TensorImpl, c10::UndefinedTensorImpl>()};
  c10::weak_intrusive_ptr<c10::TensorImpl, c10::UndefinedTensorImpl> features = alpha;
  {
    const auto r = gaussians::render(g, cam);
    alpha = c10::weak_intrusive_ptr<c10::TensorImpl, c10::UndefinedTensorImpl>(
        r.alpha.getIntrusivePtr());
    features = c10::weak_intrusive_ptr<c10::TensorImpl, c10::UndefinedTensorImpl>(
        r.features.getIntrusivePtr());
    (r.rgb.sum() + r.alpha.sum()).backward();
  }
  EXPECT_TRUE(alpha.expired());
  EXPECT_TRUE(features.expired());
  {
    const auto r = gaussians::render(g, cam);  // no backward: the graph must go as well
    alpha = c10::weak_intrusive_ptr<c10::TensorImpl, c10::UndefinedTensorImpl>(
        r.alpha.getIntrusivePtr());
  }
  EXPECT_TRUE(alpha.expired());
}

TEST(Rasterizer, BadInputsAreClearErrors) {
  const RasterCamera cam = frontCamera(8, 8, 8.0);
  auto g = randomScene(3, 2, 1);
  g.quats = at::zeros({3, 3}, g.means.options());
  try {
    gaussians::render(g, cam);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "quats");
  }
  g = randomScene(3, 2, 1);
  g.sh = g.sh.slice(1, 0, 4);
  EXPECT_THROW(gaussians::render(g, cam), Error);  // degree 3 needs 16 coefficients
  // Two parts: the first must be one coefficient, and both together must hold the degree's.
  g = randomScene(3, 2, 1);
  g.sh_rest = g.sh.narrow(1, 1, 15);
  try {
    gaussians::render(g, cam);  // sh still holds all 16
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "sh");
  }
  g.sh = g.sh.narrow(1, 0, 1);
  g.sh_rest = g.sh_rest.narrow(1, 0, 8);
  try {
    gaussians::render(g, cam);  // 9 coefficients, degree 3
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "sh");
    EXPECT_NE(std::string(e.what()).find("16"), std::string::npos) << e.what();
  }
  RasterCamera bad = cam;
  bad.fx = 0;
  EXPECT_THROW(gaussians::render(randomScene(3, 2, 1), bad), Error);
}

}  // namespace
}  // namespace sadsplat
