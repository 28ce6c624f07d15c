// View coverage: which cameras see a Gaussian's centre, the scene extent, and the floater mask,
// against hand-placed points and cameras.
#include <gtest/gtest.h>

#include <cmath>

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

TEST(ViewCoverage, SceneExtentIsTheCamerasRadiusTimes1point1) {
  // Centres (0, 0, 0) and (2, 0, 0): mean (1, 0, 0), radius 1.
  EXPECT_NEAR(gaussians::sceneExtent({viewCamera(0), viewCamera(2)}), 1.1, 1e-12);
  EXPECT_NEAR(gaussians::sceneExtent({viewCamera(0)}), 1e-3, 1e-12);  // one camera: the floor
}

}  // namespace
}  // namespace sadsplat
