// Tile lists sized before the count (tile_list_capacity.h): the capacity's arithmetic on any
// build; on a CUDA device, renders with such lists against exactly sized ones, and a short list.
#include <gtest/gtest.h>

#include <ATen/Context.h>
#include <torch/csrc/autograd/autograd.h>

#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/tile_list_capacity.h"

namespace sadsplat {
namespace {

using gaussians::GaussianParams;
using gaussians::TileListCapacity;

TEST(TileListCapacity, AMarginBelowOneIsAClearError) {
  EXPECT_THROW(TileListCapacity(0.9), Error);
  EXPECT_NO_THROW(TileListCapacity(1.0));
}

// A count sizes the next list: margin x count + 1024; without renders to check, all rendered.
TEST(TileListCapacity, ACountSizesTheNextListWithItsMargin) {
  TileListCapacity capacity(1.5);
  EXPECT_EQ(capacity.capacity(), 0);
  capacity.counted(1000);
  EXPECT_EQ(capacity.capacity(), 1500 + 1024);
  // A later exact count no longer resizes by itself; the check folds in the largest count.
  capacity.counted(4000);
  EXPECT_EQ(capacity.capacity(), 2524);
  EXPECT_TRUE(capacity.renderedAll());
  EXPECT_EQ(capacity.capacity(), 6000 + 1024);
  // Smaller counts shrink it by at most 2 % per check.
  capacity.counted(10);
  EXPECT_TRUE(capacity.renderedAll());
  EXPECT_EQ(capacity.capacity(), static_cast<std::int64_t>(0.98 * 7024));
}

GaussianParams onDevice(int n, int C, const at::Device& device) {
  at::manual_seed(23);
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  GaussianParams g;
  g.means = at::cat({(at::rand({n, 2}, opts) - 0.5) * 3.0, at::rand({n, 1}, opts) * 6.0 + 0.5}, 1);
  g.quats = at::randn({n, 4}, opts);
  g.log_scales = at::log(0.01 + 0.05 * at::rand({n, 3}, opts));
  g.opacity_logits = at::randn({n}, opts);
  g.sh = at::randn({n, 16, 3}, opts) * 0.2;
  g.features = at::randn({n, C}, opts);
  for (at::Tensor* t : {&g.means, &g.quats, &g.log_scales, &g.opacity_logits, &g.sh, &g.features}) {
    *t = t->to(device).requires_grad_(true);
  }
  return g;
}

gaussians::RasterCamera camera() {
  gaussians::RasterCamera cam;
  cam.width = 150;
  cam.height = 100;
  cam.fx = cam.fy = 110.0;
  cam.cx = 74.2;
  cam.cy = 51.7;
  return cam;
}

std::vector<at::Tensor> leaves(const GaussianParams& g) {
  return {g.means, g.quats, g.log_scales, g.opacity_logits, g.sh, g.features};
}

// Gradients of a fixed weighting of every output.
std::vector<at::Tensor> gradients(const GaussianParams& g, const gaussians::RenderResult& r) {
  at::manual_seed(5);
  const at::Tensor loss = (r.rgb * at::randn_like(r.rgb)).sum() +
                          (r.features * at::randn_like(r.features)).sum() +
                          (r.alpha * at::randn_like(r.alpha)).sum();
  return torch::autograd::grad({loss}, leaves(g));
}

// The CPU backend sizes its lists itself: a capacity in the settings changes nothing there and
// learns nothing (no count reaches it).
TEST(TileListCapacity, CpuRendersIgnoreIt) {
  const GaussianParams g = onDevice(500, 4, at::kCPU);
  gaussians::RenderSettings settings;
  settings.depth = false;
  const gaussians::RenderResult plain = gaussians::render(g, camera(), settings);
  TileListCapacity capacity;
  settings.tile_capacity = &capacity;
  const gaussians::RenderResult with = gaussians::render(g, camera(), settings);
  EXPECT_TRUE(at::equal(with.rgb, plain.rgb));
  EXPECT_TRUE(at::equal(with.features, plain.features));
  EXPECT_EQ(capacity.capacity(), 0);
  EXPECT_TRUE(capacity.renderedAll());
}

// Lists longer than the count (unused entries sort last, in no tile): the same images bit for
// bit, the same gradients to the rounding of the backward's atomic sums.
TEST(TileListCapacityCuda, ListsSizedBeforeTheCountRenderAsExactLists) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const GaussianParams g = onDevice(4000, 8, at::kCUDA);
  gaussians::RenderSettings exact_settings;
  exact_settings.depth = false;
  const gaussians::RenderResult exact = gaussians::render(g, camera(), exact_settings);

  TileListCapacity capacity(2.0);
  gaussians::RenderSettings settings = exact_settings;
  settings.tile_capacity = &capacity;
  gaussians::render(g, camera(), settings);  // counts exactly: the capacity learns the count
  ASSERT_GT(capacity.capacity(), 0);
  const gaussians::RenderResult sized = gaussians::render(g, camera(), settings);
  EXPECT_TRUE(capacity.renderedAll());
  EXPECT_TRUE(at::equal(sized.rgb, exact.rgb));
  EXPECT_TRUE(at::equal(sized.features, exact.features));
  EXPECT_TRUE(at::equal(sized.alpha, exact.alpha));
  const auto ge = gradients(g, exact), gs = gradients(g, sized);
  for (std::size_t k = 0; k < ge.size(); ++k) {
    const double scale = ge[k].abs().max().item<double>();
    EXPECT_GT(scale, 0) << k;
    EXPECT_LE((gs[k] - ge[k]).abs().max().item<double>(), 1e-5 * scale) << k;
  }
}

// A list shorter than the count is reported, the capacity grows past the count, and the next
// render has room again.
TEST(TileListCapacityCuda, AShortListIsReportedAndTheCapacityGrows) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  const GaussianParams g = onDevice(4000, 0, at::kCUDA);
  gaussians::RenderSettings settings;
  settings.depth = false;
  settings.features = false;
  const gaussians::RenderResult exact = gaussians::render(g, camera(), settings);

  TileListCapacity capacity(1.0);
  capacity.counted(100);  // far below this scene's pairs
  settings.tile_capacity = &capacity;
  const gaussians::RenderResult short_list = gaussians::render(g, camera(), settings);
  EXPECT_FALSE(capacity.renderedAll());
  EXPECT_FALSE(at::equal(short_list.rgb, exact.rgb));
  EXPECT_GT(capacity.capacity(), 1124);
  const gaussians::RenderResult again = gaussians::render(g, camera(), settings);
  EXPECT_TRUE(capacity.renderedAll());
  EXPECT_TRUE(at::equal(again.rgb, exact.rgb));
}

}  // namespace
}  // namespace sadsplat
