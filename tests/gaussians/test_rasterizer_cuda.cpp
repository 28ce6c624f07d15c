// The CUDA rasterizer against the CPU reference (runs where LibTorch has a CUDA device).
#include <gtest/gtest.h>

#include <ATen/Context.h>
#include <torch/csrc/autograd/autograd.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <iostream>
#include <utility>
#include <vector>

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace {

using gaussians::GaussianParams;

// Largest |a - b| relative to the largest |b| (b = CPU reference).
double relativeError(const at::Tensor& a, const at::Tensor& b) {
  const double scale = std::max(b.abs().max().item<double>(), 1e-12);
  return (a.cpu() - b).abs().max().item<double>() / scale;
}

GaussianParams scene(int n, int C, std::uint64_t seed) {
  at::manual_seed(seed);
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  GaussianParams g;
  // Mostly in front of the camera; some behind it and some far off-screen (culled).
  g.means = at::cat({(at::rand({n, 2}, opts) - 0.5) * 3.0, at::rand({n, 1}, opts) * 6.0 - 0.5}, 1);
  g.quats = at::randn({n, 4}, opts);
  g.log_scales = at::log(0.01 + 0.05 * at::rand({n, 3}, opts));
  g.opacity_logits = at::randn({n}, opts);
  g.sh = at::randn({n, 16, 3}, opts) * 0.2;
  g.features = at::randn({n, C}, opts);
  return g;
}

class RasterizerCuda : public ::testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  }
};

// Share of the elements of `a` (CUDA) further than 1e-4 x max|b| from `b` (CPU).
double shareOff(const at::Tensor& a, const at::Tensor& b) {
  const double scale = std::max(b.abs().max().item<double>(), 1e-12);
  return ((a.cpu() - b).abs() > 1e-4 * scale).to(at::kDouble).mean().item<double>();
}

// isolated_pixels: the forward images may differ beyond 1e-4 in at most 0.1 % of their elements
// (by at most 1 %): seen with the orthographic camera, where a few pixels differ by a few 1e-4
// (seed 49: rgb 4.5e-4, features 9.8e-4), as FMA contraction moves a Gaussian across a threshold.
// closed_gates: gates on the opacities, 30 % of them closed (0), rendered with
// closed_gate_gradients; the gates' gradients are compared too.
void expectCudaMatchesCpu(const gaussians::RasterCamera& cam, int C, bool isolated_pixels = false,
                          bool closed_gates = false) {
  gaussians::RenderSettings settings;
  settings.background = {0.3f, 0.2f, 0.1f};
  settings.closed_gate_gradients = closed_gates;
  GaussianParams cpu = scene(3000, C, 17 + C);
  GaussianParams cuda;
  std::vector<at::Tensor GaussianParams::*> members = {
      &GaussianParams::means,          &GaussianParams::quats, &GaussianParams::log_scales,
      &GaussianParams::opacity_logits, &GaussianParams::sh,    &GaussianParams::features};
  std::vector<const char*> names = {"means",          "quats", "log_scales",
                                    "opacity_logits", "sh",    "features"};
  if (closed_gates) {
    at::manual_seed(3);
    const at::Tensor u = at::rand({3000});
    cpu.opacity_gate = at::where(u < 0.3, at::zeros_like(u), u);
    members.push_back(&GaussianParams::opacity_gate);
    names.push_back("opacity_gate");
  }
  GaussianParams a = cpu;
  std::vector<at::Tensor> ta, tb;
  for (auto m : members) {
    a.*m = (cpu.*m).clone().requires_grad_(true);
    cuda.*m = (cpu.*m).to(at::kCUDA).requires_grad_(true);
    ta.push_back(a.*m);
    tb.push_back(cuda.*m);
  }
  const auto ra = gaussians::render(a, cam, settings);
  const auto rb = gaussians::render(cuda, cam, settings);
  // FMA contraction on the GPU can move a radius across an integer in rare cases.
  const int64_t radius_mismatches = (ra.radii != rb.radii.cpu()).sum().item<int64_t>();
  EXPECT_LE(radius_mismatches, 3);
  EXPECT_GT((ra.radii > 0).sum().item<int64_t>(), 1000);
  const double e_rgb = relativeError(rb.rgb, ra.rgb),
               e_feat = C ? relativeError(rb.features, ra.features) : 0,
               e_alpha = relativeError(rb.alpha, ra.alpha),
               e_depth = relativeError(rb.depth, ra.depth);
  std::cout << "C=" << C << " forward rel. error: rgb " << e_rgb << " features " << e_feat
            << " alpha " << e_alpha << " depth " << e_depth << "\n";
  const double limit = isolated_pixels ? 1e-2 : 1e-4;
  EXPECT_LT(e_rgb, limit);
  EXPECT_LT(e_feat, limit);
  EXPECT_LT(e_alpha, limit);
  EXPECT_LT(e_depth, limit);
  if (isolated_pixels) {
    const double off =
        std::max({shareOff(rb.rgb, ra.rgb), C ? shareOff(rb.features, ra.features) : 0.0,
                  shareOff(rb.alpha, ra.alpha), shareOff(rb.depth, ra.depth)});
    std::cout << "C=" << C << " share of elements off by > 1e-4: " << off << "\n";
    EXPECT_LT(off, 1e-3);
  }

  at::manual_seed(5);
  const at::Tensor w_rgb = at::randn_like(ra.rgb), w_feat = at::randn_like(ra.features),
                   w_alpha = at::randn_like(ra.alpha), w_depth = at::randn_like(ra.depth);
  auto loss = [&](const gaussians::RenderResult& r, const at::Device& d) {
    return (r.rgb * w_rgb.to(d)).sum() + (r.features * w_feat.to(d)).sum() +
           (r.alpha * w_alpha.to(d)).sum() + (r.depth * w_depth.to(d)).sum() * 0.1;
  };
  const auto ga = torch::autograd::grad({loss(ra, at::kCPU)}, ta);
  const auto gb = torch::autograd::grad({loss(rb, at::kCUDA)}, tb);
  for (std::size_t k = 0; k < ga.size(); ++k) {
    if (ga[k].numel() == 0) continue;
    const double e = relativeError(gb[k], ga[k]);
    std::cout << "C=" << C << " gradient rel. error " << names[k] << " " << e << "\n";
    EXPECT_LT(e, 2e-3) << names[k];
    EXPECT_TRUE(at::isfinite(gb[k]).all().item<bool>()) << names[k];
  }
  if (closed_gates) {  // the closed gates do get gradients
    const at::Tensor closed = cpu.opacity_gate == 0;
    EXPECT_GT(ga.back().masked_select(closed).abs().gt(0).sum().item<int64_t>(), 300);
  }
}

// The perspective camera of the CUDA-against-CPU renders: 120 x 90, principal point off centre.
gaussians::RasterCamera perspectiveCamera() {
  gaussians::RasterCamera cam;
  cam.width = 120;
  cam.height = 90;
  cam.fx = cam.fy = 100.0;
  cam.cx = 61.3;
  cam.cy = 44.1;
  return cam;
}

// Without the warp bits in the tile lists (SADSPLAT_CUDA_WARP_BITS=0: every warp takes every
// entry, the path of renders with 2^24 Gaussians or more) the CUDA renders still match the CPU.
TEST(RasterizerCudaWarpBits, WithoutWarpBitsTheRenderMatchesTheCpuReference) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const gaussians::RasterCamera cam = perspectiveCamera();
  setenv("SADSPLAT_CUDA_WARP_BITS", "0", 1);
  expectCudaMatchesCpu(cam, 3);
  expectCudaMatchesCpu(cam, 32);
  unsetenv("SADSPLAT_CUDA_WARP_BITS");
}

// Closed gates (RenderSettings::closed_gate_gradients): binned as if open, counted in `last`, a
// gradient for the gate at 0; RGB and 32 features.
TEST(RasterizerCudaClosedGates, ClosedGateGradientsMatchTheCpuReference) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  expectCudaMatchesCpu(perspectiveCamera(), 0, false, true);
  expectCudaMatchesCpu(perspectiveCamera(), 32, false, true);
}

TEST_P(RasterizerCuda, ForwardAndBackwardMatchTheCpuReference) {
  expectCudaMatchesCpu(perspectiveCamera(), GetParam());
}

// The orthographic camera (a top-down map render) through the same kernels.
TEST_P(RasterizerCuda, OrthographicForwardAndBackwardMatchTheCpuReference) {
  gaussians::RasterCamera cam;
  cam.orthographic = true;
  cam.width = 120;
  cam.height = 90;
  cam.fx = cam.fy = 35.0;  // pixels per world unit
  cam.cx = 61.3;
  cam.cy = 44.1;
  cam.qvec = {0.995, 0.0998, 0.0, 0.0};
  expectCudaMatchesCpu(cam, GetParam(), true);
}

// 0, 3, 12, 32, 64 features: every channel capacity up to 68 (4, 8, 16, 36, 68), each with its
// own forward and backward paths (values staged or not, row-wise image copies or not).
INSTANTIATE_TEST_SUITE_P(FeatureChannels, RasterizerCuda, ::testing::Values(0, 3, 12, 32, 64));

// The SH colours and their backward on CUDA against the CPU, for every degree, with exactly
// (degree+1)^2 coefficients, with more than the degree uses, and with more than 16. 1000
// Gaussians: not a multiple of the kernel's block, so the last block is partly empty.
TEST(RasterizerCudaSh, EveryDegreeAndCoefficientCountMatchesTheCpuReference) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const std::array<double, 3> centre = {0.3, -0.2, -2.0};
  const std::pair<int, int> cases[] = {{0, 1}, {1, 4}, {1, 16}, {2, 9}, {3, 16}, {3, 20}};
  for (const auto& [degree, K] : cases) {
    at::manual_seed(degree * 100 + K);
    const int n = 1000;
    const at::Tensor means = at::randn({n, 3});
    // Wide enough that some colour channels fall under 0 and are clamped (at degree 0 too).
    const at::Tensor sh = at::randn({n, K, 3}) * 2.0;
    const at::Tensor w = at::randn({n, 3});
    const at::Tensor m_cpu = means.clone().requires_grad_(true),
                     s_cpu = sh.clone().requires_grad_(true);
    const at::Tensor m_gpu = means.to(at::kCUDA).requires_grad_(true),
                     s_gpu = sh.to(at::kCUDA).requires_grad_(true);
    const at::Tensor c_cpu = gaussians::evaluateSh(s_cpu, m_cpu, centre, degree);
    const at::Tensor c_gpu = gaussians::evaluateSh(s_gpu, m_gpu, centre, degree);
    EXPECT_LT(relativeError(c_gpu, c_cpu), 1e-5) << "degree " << degree << " K " << K;
    EXPECT_GT((c_cpu == 0).sum().item<int64_t>(), 0) << "no clamped channel to test";
    const auto g_cpu = torch::autograd::grad({(c_cpu * w).sum()}, {s_cpu, m_cpu});
    const auto g_gpu = torch::autograd::grad({(c_gpu * w.to(at::kCUDA)).sum()}, {s_gpu, m_gpu});
    EXPECT_LT(relativeError(g_gpu[0], g_cpu[0]), 1e-5) << "sh, degree " << degree << " K " << K;
    EXPECT_LT(relativeError(g_gpu[1], g_cpu[1]), 1e-4) << "means, degree " << degree << " K " << K;
    // Coefficients above the degree get exactly 0.
    const int used = (degree + 1) * (degree + 1);
    if (K > used) {
      EXPECT_EQ(g_gpu[0].narrow(1, used, K - used).abs().max().item<float>(), 0.f);
    }
    // In two parts (the trainer's sh_dc and sh_rest), the rest's rows 3 (K + 1) floats apart:
    // the same colours and each part's slice of the gradient, bit for bit.
    const at::Tensor dc_gpu = sh.narrow(1, 0, 1).to(at::kCUDA).requires_grad_(true);
    const at::Tensor wide = at::cat({sh, at::zeros({n, 2, 3})}, 1).to(at::kCUDA);
    const at::Tensor rest_gpu = wide.narrow(1, 1, K - 1).detach().requires_grad_(true);
    ASSERT_TRUE(K == 1 || !rest_gpu.is_contiguous());
    const at::Tensor m2_gpu = means.to(at::kCUDA).requires_grad_(true);
    const at::Tensor c_parts = gaussians::evaluateSh(dc_gpu, rest_gpu, m2_gpu, centre, degree);
    EXPECT_TRUE(at::equal(c_parts, c_gpu)) << "degree " << degree << " K " << K;
    const auto g_parts =
        torch::autograd::grad({(c_parts * w.to(at::kCUDA)).sum()}, {dc_gpu, rest_gpu, m2_gpu});
    EXPECT_TRUE(at::equal(g_parts[0], g_gpu[0].narrow(1, 0, 1))) << "degree " << degree;
    EXPECT_TRUE(at::equal(g_parts[1], g_gpu[0].narrow(1, 1, K - 1))) << "degree " << degree;
    EXPECT_TRUE(at::equal(g_parts[2], g_gpu[1])) << "degree " << degree;
  }
}

}  // namespace
}  // namespace sadsplat
