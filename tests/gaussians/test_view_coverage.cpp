// View coverage: which cameras see a Gaussian's centre, the scene extent, and the floater mask,
// against hand-placed points and cameras.
#include <gtest/gtest.h>

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/view_coverage.h"

namespace sadsplat {
namespace {

using gaussians::RasterCamera;

// 100x100 pixels, focal length 100, looking along +z from `centre_x` on the x axis.
RasterCamera viewCamera(double centre_x) {
  RasterCamera c;
  c.width = c.height = 100;
  c.fx = c.fy = 100;
  c.cx = c.cy = 50;
  c.tvec = {-centre_x, 0, 0};  // identity rotation: t = -centre
  return c;
}

TEST(ViewCoverage, CountsTheCamerasThatSeeEachCentre) {
  const std::vector<RasterCamera> cameras = {viewCamera(0), viewCamera(2)};
  // In front of both; behind both; in front but outside both images; seen by the first only
  // (x = -1 at z = 5: u = 100 * -1 / 5 + 50 = 30 for the first, 100 * -3 / 5 + 50 = -10 for the
  // second).
  const at::Tensor means =
      at::tensor({1.0, 0.0, 5.0, 1.0, 0.0, -5.0, 40.0, 0.0, 1.0, -1.0, 0.0, 5.0}, at::kFloat)
          .view({4, 3});
  const at::Tensor counts = gaussians::viewCounts(means, cameras);
  ASSERT_EQ(counts.scalar_type(), at::kInt);
  EXPECT_EQ(counts[0].item<int>(), 2);
  EXPECT_EQ(counts[1].item<int>(), 0);
  EXPECT_EQ(counts[2].item<int>(), 0);
  EXPECT_EQ(counts[3].item<int>(), 1);

  // Floaters: seen by fewer than 2 views, or a largest scale above 3 (exp(log 4) = 4 > 3).
  const at::Tensor log_scales =
      at::log(at::tensor({1.0, 1.0, 4.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0}, at::kFloat))
          .view({4, 3});
  const at::Tensor views_only = gaussians::floaterMask(means, log_scales, cameras, 2, 0);
  EXPECT_FALSE(views_only[0].item<bool>());
  EXPECT_TRUE(views_only[1].item<bool>());
  EXPECT_TRUE(views_only[3].item<bool>());
  const at::Tensor size_only = gaussians::floaterMask(means, log_scales, cameras, 0, 3.0);
  EXPECT_TRUE(size_only[0].item<bool>());
  EXPECT_EQ(size_only.sum().item<int>(), 1);
  EXPECT_EQ(gaussians::floaterMask(means, log_scales, cameras, 0, 0).sum().item<int>(), 0);
}

TEST(ViewCoverage, PixelsCountTheTrainingViewsThatSeeTheirSurface) {
  // The evaluated view is the camera at x = 0, the surface a plane at depth 5. A pixel's centre
  // u + 0.5 back-projects to x = (u + 0.5 - 50) / 100 * 5, which the camera at x = 2 sees at
  // u' = u + 0.5 - 40: inside its image from column 40 on. One pixel renders nothing.
  const at::Tensor depth = at::full({100, 100}, 5.0, at::kFloat);
  at::Tensor alpha = at::ones({100, 100}, at::kFloat);
  alpha[7][70] = 0.2;
  const at::Tensor counts =
      gaussians::pixelViewCounts(depth, alpha, viewCamera(0), {viewCamera(0), viewCamera(2)});
  ASSERT_EQ(counts.sizes(), at::IntArrayRef({100, 100}));
  ASSERT_EQ(counts.scalar_type(), at::kInt);
  EXPECT_EQ(counts[50][0].item<int>(), 1);
  EXPECT_EQ(counts[50][39].item<int>(), 1);
  EXPECT_EQ(counts[50][40].item<int>(), 2);
  EXPECT_EQ(counts[99][99].item<int>(), 2);
  EXPECT_EQ(counts[7][70].item<int>(), 0);
  EXPECT_EQ(counts.eq(2).sum().item<int>(), 60 * 100 - 1);
  // In blocks of 4 (column 40 starts one), and of 3 (columns 39-41 share pixel 40's count; the
  // last block, column 99, is cut by the image's edge: its own pixel stands for it).
  EXPECT_TRUE(at::equal(gaussians::pixelViewCounts(depth, alpha, viewCamera(0),
                                                   {viewCamera(0), viewCamera(2)}, 0.5, 4),
                        counts));
  const at::Tensor by3 = gaussians::pixelViewCounts(depth, alpha, viewCamera(0),
                                                    {viewCamera(0), viewCamera(2)}, 0.5, 3);
  ASSERT_EQ(by3.sizes(), at::IntArrayRef({100, 100}));
  EXPECT_EQ(by3[50][38].item<int>(), 1);
  EXPECT_EQ(by3[50][39].item<int>(), 2);
  EXPECT_EQ(by3[99][99].item<int>(), 2);
  EXPECT_EQ(by3[7][70].item<int>(), 0);

  // A rotated, moved camera sees every pixel it back-projects (a transposed rotation would not):
  // 90 degrees about x, then 30 about y, centre away from the origin.
  RasterCamera turned = viewCamera(0);
  const double h = std::sqrt(0.5), c15 = std::cos(M_PI / 12), s15 = std::sin(M_PI / 12);
  turned.qvec = {h * c15, h * c15, h * s15, -h * s15};  // q_y(30) * q_x(90)
  turned.tvec = {0.3, -1.0, 2.0};
  const at::Tensor self = gaussians::pixelViewCounts(
      at::full({100, 100}, 3.0, at::kFloat), at::ones({100, 100}, at::kFloat), turned, {turned});
  EXPECT_EQ(self.sum().item<int>(), 100 * 100);
  // Every pixel's surface lies 3 in front of the centre: the same camera moved 4 along its axis
  // has all of it 1 behind it.
  RasterCamera beyond = turned;
  beyond.tvec = {turned.tvec[0], turned.tvec[1], turned.tvec[2] - 4.0};
  const at::Tensor behind = gaussians::pixelViewCounts(
      at::full({100, 100}, 3.0, at::kFloat), at::ones({100, 100}, at::kFloat), turned, {beyond});
  EXPECT_EQ(behind.sum().item<int>(), 0);

  EXPECT_THROW(gaussians::pixelViewCounts(at::ones({10, 10}), at::ones({10, 10}), viewCamera(0),
                                          {viewCamera(0)}),
               Error);
}

TEST(ViewCoverage, SparseDepthIsTheMedianPerBlockFilledFromTheNearestBlock) {
  // Camera at x = 0 (100x100, f = 100), blocks of 10 pixels. Points at depth 5 project into
  // columns 0-9 (x = -2.4 .. -2.1 at z = 5: u = 2 .. 8), a far point alone in its block;
  // points at depth 10 into columns 90-99; one point behind the camera and one outside the image.
  std::vector<double> xyz;
  for (double y : {-0.2, 0.0, 0.2}) {
    for (double x : {-2.4, -2.3, -2.1}) xyz.insert(xyz.end(), {x, y, 5.0});
    for (double x : {4.2, 4.5}) xyz.insert(xyz.end(), {x, y, 10.0});
  }
  xyz.insert(xyz.end(), {-20.0, 0.0, 50.0});  // (u, v) = (10, 50): block (5, 1), alone
  xyz.insert(xyz.end(), {0.0, 0.0, -5.0});    // behind
  xyz.insert(xyz.end(), {100.0, 0.0, 5.0});   // outside
  const at::Tensor points = at::tensor(xyz, at::kDouble).view({-1, 3}).to(at::kFloat);
  const at::Tensor depth = gaussians::sparseDepthImage(points, viewCamera(0), 10);
  ASSERT_TRUE(depth.defined());
  ASSERT_EQ(depth.sizes(), at::IntArrayRef({100, 100}));
  EXPECT_FLOAT_EQ(depth[50][5].item<float>(), 5.0f);    // its own block
  EXPECT_FLOAT_EQ(depth[55][15].item<float>(), 50.0f);  // the lone far point's block
  EXPECT_FLOAT_EQ(depth[50][95].item<float>(), 10.0f);
  EXPECT_FLOAT_EQ(depth[0][0].item<float>(), 5.0f);  // empty: the nearest filled block
  EXPECT_FLOAT_EQ(depth[99][85].item<float>(), 10.0f);
  // Nothing in front and inside: no depth.
  EXPECT_FALSE(
      gaussians::sparseDepthImage(at::tensor({0.0, 0.0, -5.0}).view({1, 3}), viewCamera(0), 10)
          .defined());
}

TEST(ViewCoverage, TheSceneSparsePointsAsATensor) {
  io::Scene scene;
  EXPECT_FALSE(gaussians::sparsePointTensor(scene).defined());
  io::ScenePoint a, b;
  a.xyz = {1, 2, 3};
  b.xyz = {-4, 5.5f, 0};
  scene.points = {a, b};
  const at::Tensor t = gaussians::sparsePointTensor(scene);
  ASSERT_EQ(t.sizes(), (std::vector<std::int64_t>{2, 3}));
  EXPECT_EQ(t.scalar_type(), at::kFloat);
  EXPECT_TRUE(at::equal(t, at::tensor({1.f, 2.f, 3.f, -4.f, 5.5f, 0.f}).view({2, 3})));
}

TEST(ViewCoverage, SparseSamplesAreThePointsNoNearerPointOfTheirBlockHides) {
  // Camera at the origin looking along +z: (x, y, z) lands at u = 100 x / z + 50, v likewise;
  // 16-pixel blocks. Points 0-3 fall in the block of columns and rows 48-63:
  // 0: (0, 0, 5) -> (50, 50), the block's nearest. 1: (0.02, 0, 10) -> (50.2, 50).
  // 2: (0.5, 0, 10.2) -> (54.9, 50). 3: (0.5, 0.5, 10.1) -> (54.95, 54.95).
  // 4: (-4, 0, 10) -> (10, 50), alone in its block. 5: behind the camera. 6: outside the image.
  const at::Tensor points = at::tensor({0.0,  0.0,  5.0, 0.02, 0.0, 10.0, 0.5,  0.0, 10.2, 0.5, 0.5,
                                        10.1, -4.0, 0.0, 10.0, 0.0, 0.0,  -5.0, 9.0, 0.0,  5.0},
                                       at::kFloat)
                                .view({7, 3});
  // Point 0 hides 1-3 (5 m behind it, far beyond 3 % of their depth).
  const gaussians::SparseDepthSamples s =
      gaussians::visibleSparseDepths(points, viewCamera(0), 16, 0.03);
  ASSERT_EQ(s.size(), 2);
  EXPECT_EQ(s.pixels[0].item<std::int64_t>(), 50 * 100 + 50);
  EXPECT_FLOAT_EQ(s.depths[0].item<float>(), 5.0f);
  EXPECT_EQ(s.pixels[1].item<std::int64_t>(), 50 * 100 + 10);
  EXPECT_FLOAT_EQ(s.depths[1].item<float>(), 10.0f);
  // Without point 0 the block's front is point 1 at 10: point 3 (0.1 behind) is within 1 % and
  // 3 % of its depth, point 2 (0.2 behind) only within 3 %.
  const at::Tensor rest = points.slice(0, 1);
  EXPECT_EQ(gaussians::visibleSparseDepths(rest, viewCamera(0), 16, 0.03).size(), 4);
  const gaussians::SparseDepthSamples tight =
      gaussians::visibleSparseDepths(rest, viewCamera(0), 16, 0.01);
  ASSERT_EQ(tight.size(), 3);
  EXPECT_FLOAT_EQ(tight.depths[1].item<float>(), 10.1f);
  // Blocks of one pixel: only point 1 shares a pixel (50, 50) with a nearer point.
  EXPECT_EQ(gaussians::visibleSparseDepths(points, viewCamera(0), 1, 0.03).size(), 4);
  EXPECT_THROW(gaussians::visibleSparseDepths(at::zeros({3}), viewCamera(0)), Error);
}

TEST(ViewCoverage, SceneExtentIsTheCamerasRadiusTimes1point1) {
  // Centres (0, 0, 0) and (2, 0, 0): mean (1, 0, 0), radius 1.
  EXPECT_NEAR(gaussians::sceneExtent({viewCamera(0), viewCamera(2)}), 1.1, 1e-12);
  EXPECT_NEAR(gaussians::sceneExtent({viewCamera(0)}), 1e-3, 1e-12);  // one camera: the floor
}

}  // namespace
}  // namespace sadsplat

namespace sadsplat {
namespace {

TEST(ViewCoverage, AViewSeesOnlyWhatItsDepthImageShows) {
  // The camera at the origin sees a wall at depth 5 (alpha 1), except one pixel with no surface.
  const gaussians::RasterCamera c = viewCamera(0);
  const at::Tensor depth = at::full({100, 100}, 5.0, at::kFloat);
  at::Tensor alpha = at::ones({100, 100}, at::kFloat);
  alpha[50][50] = 0.2;  // the pixel of (0.005, 0.005, z) for any z: u = 100 x / z + 50
  // On the wall; behind it (occluded); in front of it (a point the view looks through); on the
  // wall within 2 %; outside the image; where the image shows nothing.
  const at::Tensor points = at::tensor({1.0, 1.0, 5.0, 1.0, 1.0, 8.0, 1.0, 1.0, 3.0, 1.0, 1.0, 5.09,
                                        40.0, 0.0, 5.0, 0.0051, 0.0051, 5.0},
                                       at::kDouble)
                                .view({6, 3});
  const at::Tensor seen = gaussians::seenUnoccluded(points, c, depth, alpha, 0.02);
  ASSERT_EQ(seen.scalar_type(), at::kBool);
  const std::vector<bool> expected = {true, false, false, true, false, false};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(seen[i].item<bool>(), expected[i]) << i;
  EXPECT_THROW(gaussians::seenUnoccluded(points, c, depth.view({10, 1000}), alpha), Error);
}

}  // namespace
}  // namespace sadsplat
