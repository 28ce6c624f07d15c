// The CPU rasterizer's vectorised tile loops (raster_cpu_tiles.h) against its scalar reference
// loops: images, alphas, last contributors and every gradient must be bit-identical, in images
// whose edge tiles have partial rows and with lists long enough for pixels to saturate.
#include <gtest/gtest.h>

#include <cstdint>

#include "raster_backend.h"

namespace sadsplat {
namespace {

using gaussians::raster::CameraParams;
using gaussians::raster::CpuTileLoops;

CameraParams frontCamera(int width, int height, double f) {
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

// n float Gaussians in front of the camera, projected with the CPU backend; D channels.
Scene projectedScene(int n, int D, const CameraParams& cam, std::uint64_t seed, double opacity) {
  at::manual_seed(static_cast<int64_t>(seed));
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  const at::Tensor means =
      at::cat({(at::rand({n, 2}, opts) - 0.5) * 1.2, 2.0 + at::rand({n, 1}, opts)}, 1);
  const at::Tensor quats = at::randn({n, 4}, opts);
  const at::Tensor log_scales = at::log(0.01 + 0.08 * at::rand({n, 3}, opts));
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

// coverage: the largest alpha the scene must reach (0.999: pixels near saturation, which stop at
// a transmittance of 1e-4).
void expectPathsAgree(int width, int height, int n, int D, double opacity, double coverage,
                      std::uint64_t seed) {
  SCOPED_TRACE(testing::Message() << width << "x" << height << ", " << n << " Gaussians, D " << D
                                  << ", opacity up to " << opacity);
  const CameraParams cam = frontCamera(width, height, 0.9 * width);
  const Scene s = projectedScene(n, D, cam, seed, opacity);
  using gaussians::raster::rasterizeBackwardCpu;
  using gaussians::raster::rasterizeForwardCpu;
  const auto fast = rasterizeForwardCpu(s.means2d, s.conics, s.opacities, s.values, s.radii,
                                        s.depths, width, height, CpuTileLoops::kFastest);
  const auto scalar = rasterizeForwardCpu(s.means2d, s.conics, s.opacities, s.values, s.radii,
                                          s.depths, width, height, CpuTileLoops::kScalar);
  ASSERT_GT(scalar.alpha.max().item<float>(), coverage) << "the scene must cover pixels";
  expectBitIdentical(fast.image, scalar.image, "image");
  expectBitIdentical(fast.alpha, scalar.alpha, "alpha");
  expectBitIdentical(fast.last, scalar.last, "last");

  at::manual_seed(static_cast<int64_t>(seed) + 1);
  const at::Tensor g_image = at::randn({height, width, D});
  const at::Tensor g_alpha = at::randn({height, width});
  const auto gf = rasterizeBackwardCpu(s.means2d, s.conics, s.opacities, s.values, scalar, g_image,
                                       g_alpha, CpuTileLoops::kFastest);
  const auto gs = rasterizeBackwardCpu(s.means2d, s.conics, s.opacities, s.values, scalar, g_image,
                                       g_alpha, CpuTileLoops::kScalar);
  ASSERT_GT(gs.opacities.abs().sum().item<float>(), 0.f) << "the gradients must not all be 0";
  expectBitIdentical(gf.means2d, gs.means2d, "means2d gradient");
  expectBitIdentical(gf.conics, gs.conics, "conics gradient");
  expectBitIdentical(gf.opacities, gs.opacities, "opacities gradient");
  expectBitIdentical(gf.values, gs.values, "values gradient");
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

TEST(RasterCpuPaths, FaintGaussiansThatNeverSaturateAreBitIdentical) {
  expectPathsAgree(40, 40, 800, 3, 0.05, 0.2, 4);
}

}  // namespace
}  // namespace sadsplat
