// The CPU rasterizer's vectorised tile loops (the SSE2 rows of raster_cpu_tiles.h, the AVX2 and
// AVX-512 lanes of raster_cpu_lanes.h, each where this CPU runs it) against its scalar reference
// loops: images, alphas, last contributors and every gradient must be bit-identical, in images
// whose edge tiles have partial rows and with lists long enough for pixels to saturate.
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "raster_backend.h"
#include "raster_cpu_tiles.h"

namespace sadsplat {
namespace {

using gaussians::raster::CameraParams;
using gaussians::raster::CpuTileLoops;

CameraParams frontCameraParams(int width, int height, double f) {
  CameraParams c;
  c.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  c.fx = c.fy = f;
  c.cx = width / 2.0;
  c.cy = height / 2.0;
  c.width = width;
  c.height = height;
  return c;
}

struct Scene {
  at::Tensor means2d, conics, opacities, values, radii, depths;
};

// n float Gaussians in front of the camera, projected with the CPU backend; D channels. needles:
// scales from 0.001 to 0.3 per axis (cubed uniform), so many are thin and long, at every angle.
Scene projectedScene(int n, int D, const CameraParams& cam, std::uint64_t seed, double opacity,
                     bool needles = false) {
  at::manual_seed(static_cast<int64_t>(seed));
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  const at::Tensor means =
      at::cat({(at::rand({n, 2}, opts) - 0.5) * 1.2, 2.0 + at::rand({n, 1}, opts)}, 1);
  const at::Tensor quats = at::randn({n, 4}, opts);
  const at::Tensor log_scales = needles ? at::log(0.001 + 0.3 * at::rand({n, 3}, opts).pow(3))
                                        : at::log(0.01 + 0.08 * at::rand({n, 3}, opts));
  const auto p = gaussians::raster::projectForwardCpu(means, quats, log_scales, cam);
  Scene s;
  s.means2d = p.means2d;
  s.conics = p.conics;
  s.depths = p.depths;
  s.radii = p.radii;
  s.opacities = at::rand({n}, opts) * opacity;
  s.values = at::randn({n, D}, opts);
  return s;
}

void expectBitIdentical(const at::Tensor& a, const at::Tensor& b, const char* what) {
  ASSERT_EQ(a.sizes(), b.sizes()) << what;
  EXPECT_TRUE(at::equal(a, b))
      << what << ": largest difference "
      << (a.to(at::kDouble) - b.to(at::kDouble)).abs().max().item<double>();
}

// The vectorised loops this CPU runs (a test with none of them checks nothing and says so).
std::vector<std::pair<CpuTileLoops, const char*>> vectorisedLoops() {
  std::vector<std::pair<CpuTileLoops, const char*>> loops;
  for (const auto& [l, name] : {std::pair{CpuTileLoops::kRows, "SSE2 rows"},
                                {CpuTileLoops::kLanesAvx2, "AVX2 lanes"},
                                {CpuTileLoops::kLanesAvx512, "AVX-512 lanes"}}) {
    if (gaussians::raster::cpuTileLoopsAvailable(l)) loops.emplace_back(l, name);
  }
  return loops;
}

// coverage: the largest alpha the scene must reach (0.999: pixels near saturation, which stop at
// a transmittance of 1e-4). closed_share: that share of the Gaussians (at random) gets its
// opacity negated, a closed gate (raster_backend.h).
void expectPathsAgree(int width, int height, int n, int D, double opacity, double coverage,
                      std::uint64_t seed, bool needles = false, double closed_share = 0) {
  SCOPED_TRACE(testing::Message() << width << "x" << height << ", " << n << " Gaussians, D " << D
                                  << ", opacity up to " << opacity << ", closed " << closed_share);
  const CameraParams cam = frontCameraParams(width, height, 0.9 * width);
  Scene s = projectedScene(n, D, cam, seed, opacity, needles);
  if (closed_share > 0) {
    s.opacities = at::where(at::rand({n}) < closed_share, -s.opacities, s.opacities);
  }
  using gaussians::raster::rasterizeBackwardCpu;
  using gaussians::raster::rasterizeForwardCpu;
  auto scalar = rasterizeForwardCpu(s.means2d, s.conics, s.opacities, s.values, s.radii, s.depths,
                                    width, height, CpuTileLoops::kScalar);
  scalar.closed_gates = closed_share > 0;
  ASSERT_GT(scalar.alpha.max().item<float>(), coverage) << "the scene must cover pixels";
  at::manual_seed(static_cast<int64_t>(seed) + 1);
  const at::Tensor g_image = at::randn({height, width, D});
  const at::Tensor g_alpha = at::randn({height, width});
  const auto gs = rasterizeBackwardCpu(s.means2d, s.conics, s.opacities, s.values, scalar, g_image,
                                       g_alpha, CpuTileLoops::kScalar);
  ASSERT_GT(gs.opacities.abs().sum().item<float>(), 0.f) << "the gradients must not all be 0";
  if (closed_share > 0) {  // closed gates get opacity gradients, and only with the flag
    const at::Tensor closed = s.opacities < 0;
    EXPECT_GT(gs.opacities.masked_select(closed).abs().sum().item<float>(), 0.f);
    auto unflagged = scalar;
    unflagged.closed_gates = false;
    const auto gu = rasterizeBackwardCpu(s.means2d, s.conics, s.opacities, s.values, unflagged,
                                         g_image, g_alpha, CpuTileLoops::kScalar);
    EXPECT_EQ(gu.opacities.masked_select(closed).abs().max().item<float>(), 0.f);
  }
  const auto loops = vectorisedLoops();
  if (loops.empty()) GTEST_SKIP() << "this build or CPU has no vectorised tile loops";
  for (const auto& [l, name] : loops) {
    SCOPED_TRACE(name);
    const auto fast = rasterizeForwardCpu(s.means2d, s.conics, s.opacities, s.values, s.radii,
                                          s.depths, width, height, l);
    expectBitIdentical(fast.image, scalar.image, "image");
    expectBitIdentical(fast.alpha, scalar.alpha, "alpha");
    expectBitIdentical(fast.last, scalar.last, "last");
    const auto gf = rasterizeBackwardCpu(s.means2d, s.conics, s.opacities, s.values, scalar,
                                         g_image, g_alpha, l);
    expectBitIdentical(gf.means2d, gs.means2d, "means2d gradient");
    expectBitIdentical(gf.conics, gs.conics, "conics gradient");
    expectBitIdentical(gf.opacities, gs.opacities, "opacities gradient");
    expectBitIdentical(gf.values, gs.values, "values gradient");
  }
}

// kFastest is one of the loops above, so it renders as they do.
TEST(RasterCpuPaths, FastestIsBitIdenticalToTheScalarLoops) {
  const CameraParams cam = frontCameraParams(48, 40, 0.9 * 48);
  const Scene s = projectedScene(1500, 3, cam, 11, 0.95);
  using gaussians::raster::rasterizeForwardCpu;
  const auto fast = rasterizeForwardCpu(s.means2d, s.conics, s.opacities, s.values, s.radii,
                                        s.depths, 48, 40, CpuTileLoops::kFastest);
  const auto scalar = rasterizeForwardCpu(s.means2d, s.conics, s.opacities, s.values, s.radii,
                                          s.depths, 48, 40, CpuTileLoops::kScalar);
  expectBitIdentical(fast.image, scalar.image, "image");
  expectBitIdentical(fast.last, scalar.last, "last");
}

// expPoly, the exp of every CPU pixel alpha: within 2 ulp of exp (in double, rounded to float)
// over the whole clamped range and at the powers alphas come from; NaN stays NaN.
TEST(RasterCpuPaths, ExpPolyIsWithinTwoUlpOfExp) {
  const auto ulps = [](float a, float b) {
    int32_t ia, ib;
    std::memcpy(&ia, &a, sizeof ia);
    std::memcpy(&ib, &b, sizeof ib);
    return std::abs(static_cast<int64_t>(ia) - ib);
  };
  int64_t worst = 0;
  for (int i = 0; i <= 400000; ++i) {
    const float x = -87.f + 175.f * float(i) / 400000.f;
    worst = std::max(worst, ulps(gaussians::raster::expPoly(x), float(std::exp(double(x)))));
  }
  for (int i = 0; i <= 100000; ++i) {
    const float x = -6.f * float(i) / 100000.f;
    worst = std::max(worst, ulps(gaussians::raster::expPoly(x), float(std::exp(double(x)))));
  }
  EXPECT_LE(worst, 2);
  EXPECT_EQ(gaussians::raster::expPoly(0.f), 1.f);
  EXPECT_TRUE(std::isnan(gaussians::raster::expPoly(std::nanf(""))));
  EXPECT_GT(gaussians::raster::expPoly(-200.f), 0.f);  // clamped to exp(-87), not 0 or garbage
}

TEST(RasterCpuPaths, RgbRendersAndGradientsAreBitIdenticalToTheScalarLoops) {
  expectPathsAgree(64, 48, 3000, 3, 0.95, 0.999, 1);
}

TEST(RasterCpuPaths, PartialEdgeTilesAreBitIdentical) {
  // 37 x 29: the last tile column holds 5 pixels per row, the last tile row 13 rows.
  expectPathsAgree(37, 29, 1500, 3, 0.95, 0.999, 2);
}

TEST(RasterCpuPaths, FeatureChannelsAreBitIdentical) {
  expectPathsAgree(45, 33, 1200, 35, 0.9, 0.999, 3);
}

// Channel counts around the lanes' vector widths (8 and 16 floats): whole vectors, whole vectors
// and a tail, a tail only.
TEST(RasterCpuPaths, ChannelCountsAroundTheVectorWidthsAreBitIdentical) {
  for (const int D : {1, 2, 8, 16, 17, 32}) expectPathsAgree(33, 21, 700, D, 0.9, 0.99, 20 + D);
}

TEST(RasterCpuPaths, FaintGaussiansThatNeverSaturateAreBitIdentical) {
  expectPathsAgree(40, 40, 800, 3, 0.05, 0.2, 4);
}

// Thin, long Gaussians at every angle: the vectorised loops leave out the rows outside each
// Gaussian's row range (rowRange), which must never hold a pixel that the skip test passes.
TEST(RasterCpuPaths, ThinRotatedGaussiansAreBitIdentical) {
  expectPathsAgree(64, 48, 2500, 3, 0.95, 0.999, 5, true);
  expectPathsAgree(45, 33, 1200, 35, 0.9, 0.999, 6, true);
}

// Closed gates: the lane loops hand such renders to the rows (or scalar) loops; every loop gives
// the scalar loops' bits, and the closed gates get opacity gradients.
TEST(RasterCpuPaths, ClosedGatesAreBitIdentical) {
  expectPathsAgree(64, 48, 3000, 3, 0.95, 0.999, 8, false, 0.3);
  expectPathsAgree(45, 33, 1200, 35, 0.9, 0.999, 9, true, 0.3);
}

// rowRange directly: on the first pixel-centre rows outside the range of random Gaussians (thin
// ones and high opacities included), no pixel of a wide span of x passes the skip test as the
// vectorised loops compute it (gaussianPower in float).
// The tile lists of the CPU binning: each tile holds exactly the Gaussians whose alpha ellipse
// meets it, ordered by (float depth, id) — the order the CUDA backend's stable sort gives —
// whatever the thread count. Depths rounded to quarters give many equal depths, so ties must
// keep the ids' order, in lists both short (a plain sort) and long (the radix sort); more
// Gaussians than one binning run.
TEST(RasterCpuPaths, TileListsAreInDepthThenIdOrderWithAnyThreadCount) {
  const int width = 70, height = 50;
  const CameraParams cam = frontCameraParams(width, height, 60.0);
  Scene s = projectedScene(9000, 3, cam, 21, 0.9);
  s.depths = at::round(s.depths * 4) / 4;
  // Reference: per tile, the ids that meet it (in id order), stable-sorted by depth.
  const auto [tiles_x, tiles_y] = gaussians::raster::tileGrid(width, height);
  std::vector<std::vector<int>> expected(static_cast<std::size_t>(tiles_x * tiles_y));
  const float* m2 = s.means2d.data_ptr<float>();
  const float* co = s.conics.data_ptr<float>();
  const float* op = s.opacities.data_ptr<float>();
  const float* depth = s.depths.data_ptr<float>();
  const int* radii = s.radii.data_ptr<int>();
  for (int i = 0; i < 9000; ++i) {
    gaussians::raster::AlphaEllipse<float> e;
    if (!gaussians::raster::alphaEllipse(m2 + 2 * i, co + 3 * i, op[i], &e)) continue;
    int rx, ry;
    gaussians::raster::alphaBox(radii[i], e, &rx, &ry);
    if (rx <= 0) continue;
    int x0, y0, x1, y1;
    gaussians::raster::tileRect(m2 + 2 * i, rx, ry, tiles_x, tiles_y, &x0, &y0, &x1, &y1);
    for (int ty = y0; ty < y1; ++ty) {
      for (int tx = x0; tx < x1; ++tx) {
        if (gaussians::raster::alphaEllipseMeetsTile(e, tx, ty)) {
          expected[ty * tiles_x + tx].push_back(i);
        }
      }
    }
  }
  std::size_t longest = 0, shortest = SIZE_MAX;
  for (auto& list : expected) {
    std::stable_sort(list.begin(), list.end(), [&](int a, int b) { return depth[a] < depth[b]; });
    longest = std::max(longest, list.size());
    shortest = std::min(shortest, list.size());
  }
  ASSERT_GT(longest, 1000u);  // the radix sort's lists
  ASSERT_LE(shortest, 64u);   // and the short ones'
  const int threads = at::get_num_threads();
  for (const int t : {1, 2, 3}) {
    at::set_num_threads(t);
    const auto r =
        gaussians::raster::rasterizeForwardCpu(s.means2d, s.conics, s.opacities, s.values, s.radii,
                                               s.depths, width, height, CpuTileLoops::kFastest);
    const int* ranges = r.binning.tile_ranges.data_ptr<int>();
    const int* ids = r.binning.gaussian_ids.data_ptr<int>();
    for (int tile = 0; tile < tiles_x * tiles_y; ++tile) {
      const std::vector<int> got(ids + ranges[2 * tile], ids + ranges[2 * tile + 1]);
      ASSERT_EQ(got, expected[tile]) << "tile " << tile << ", " << t << " threads";
    }
  }
  at::set_num_threads(threads);
}

TEST(RasterCpuPaths, NoPixelOutsideTheRowRangePassesTheSkipTest) {
  at::manual_seed(7);
  const int n = 20000;
  const at::Tensor u = at::rand({n, 6}, at::kDouble);
  int rows_checked = 0;
  for (int i = 0; i < n; ++i) {
    const auto r = [&](int k) { return u[i][k].item<double>(); };
    // Covariance from two axis variances (0.3 .. ~1e4 px^2) and an angle.
    const double s1 = 0.3 + 1e4 * std::pow(r(0), 4), s2 = 0.3 + 1e4 * std::pow(r(1), 4);
    const double t = 3.14159265 * r(2), c = std::cos(t), sn = std::sin(t);
    const double sxx = c * c * s1 + sn * sn * s2, syy = sn * sn * s1 + c * c * s2,
                 sxy = c * sn * (s1 - s2), det = sxx * syy - sxy * sxy;
    const float conic[3] = {float(syy / det), float(-sxy / det), float(sxx / det)};
    const float opacity = float(0.005 + 0.995 * r(3));
    const float skip = std::log(float(gaussians::raster::kMinAlpha) / opacity) - 1e-3f;
    const float mean_y = float(100.0 * r(4)), mean_x = float(100.0 * r(5));
    float lo = 0, hi = 0;
    gaussians::raster::cpu_tiles::rowRange(mean_y, conic, skip, &lo, &hi);
    ASSERT_TRUE(std::isfinite(lo) && std::isfinite(hi) && lo <= mean_y && mean_y <= hi) << i;
    // The nearest pixel-centre rows outside [lo, hi].
    const float above = std::floor(lo - 0.5f) + 0.5f, below = std::ceil(hi - 0.5f) + 0.5f;
    for (const float fy : {above < lo ? above : above - 1.f, below > hi ? below : below + 1.f}) {
      const float half_width = float(std::sqrt(-2.0 * skip * sxx)) + 2.f;
      for (float fx = std::floor(mean_x - half_width) + 0.5f; fx <= mean_x + half_width;
           fx += 1.f) {
        const float power = gaussians::raster::gaussianPower(conic, mean_x - fx, mean_y - fy);
        ASSERT_LT(power, skip) << "Gaussian " << i << " row " << fy << " x " << fx;
      }
      ++rows_checked;
    }
  }
  EXPECT_EQ(rows_checked, 2 * n);
}

}  // namespace
}  // namespace sadsplat
