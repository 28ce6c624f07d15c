// The training-memory estimate counts the views as the trainer keeps them: held, every training
// view's picture, mask, labels and confidence map; streamed, the confidence maps only (and one
// step's uploads). Checked against the tensors loadTrainingViews makes, and the Gaussians' part
// against its stated growth and cap.
#include <gtest/gtest.h>

#include <cstdint>
#include <utility>

#include "sadsplat/gaussians/memory_estimate.h"
#include "training_views.h"

namespace sadsplat {
namespace {

io::View view(int w, int h, bool train) {
  io::View v;
  v.camera.width = w;
  v.camera.height = h;
  v.camera.fx = v.camera.fy = w;
  v.camera.cx = w / 2.0;
  v.camera.cy = h / 2.0;
  v.rgb = {w, h, 3, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3, 100)};
  v.mask = {w, h, 1, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h, 255)};
  v.train = train;
  return v;
}

// Four views of different sizes: a labelled one, a pseudo-labelled one, a plain training view,
// and a test view (not held).
io::Scene mixedScene() {
  io::Scene s;
  io::View labelled = view(12, 8, true);
  labelled.labelled = true;
  labelled.labels = {12, 8, 1, std::vector<std::uint8_t>(96, 1)};
  io::View pseudo = view(10, 6, true);
  pseudo.pseudo.backend = "builtin";
  pseudo.pseudo.region.assign(60, 0);
  pseudo.pseudo.num_targets = 1;
  pseudo.pseudo.num_classes = 2;
  pseudo.pseudo.scores = {0.2f, 0.8f};
  pseudo.pseudo.kept = {1};
  s.views.push_back(std::move(labelled));
  s.views.push_back(std::move(pseudo));
  s.views.push_back(view(9, 7, true));
  s.views.push_back(view(20, 20, false));
  for (int i = 0; i < 10; ++i) s.points.push_back({{0.1f * static_cast<float>(i), 0.f, 0.f}, {128, 128, 128}});
  return s;
}

std::int64_t bytes(const at::Tensor& t) { return t.defined() ? t.numel() * t.element_size() : 0; }

TEST(MemoryEstimate, HeldViewsAreTheTensorsTheTrainerLoads) {
  const io::Scene scene = mixedScene();
  gaussians::TrainConfig config;
  const gaussians::TrainingViews views =
      gaussians::loadTrainingViews(scene, config, at::Device(at::kCPU));
  std::int64_t held = 0;
  for (int v : views.train_views) {
    held += bytes(views.images[v]) + bytes(views.masks[v]) + bytes(views.labels[v]) +
            bytes(views.confidence_maps[v]);
  }
  const gaussians::MemoryEstimate e = gaussians::estimateTrainingMemory(scene, config);
  EXPECT_EQ(e.views, held);
  EXPECT_EQ(e.fixed, 0);  // a CPU device has no CUDA context
  // One step renders a view and a labelled one at the largest training view's size (12 x 8).
  EXPECT_GT(e.render, 0);
  EXPECT_EQ(e.render % (2 * 12 * 8 * 4), 0);
}

TEST(MemoryEstimate, StreamedViewsLeaveTheConfidenceMapsAndOneStepsUploads) {
  const io::Scene scene = mixedScene();
  gaussians::TrainConfig config;
  config.stream_views = true;
  const gaussians::TrainingViews views =
      gaussians::loadTrainingViews(scene, config, at::Device(at::kCPU));
  std::int64_t on_device = 0;
  for (int v : views.train_views) on_device += bytes(views.confidence_maps[v]);
  ASSERT_GT(on_device, 0);
  const gaussians::MemoryEstimate e = gaussians::estimateTrainingMemory(scene, config);
  // The uploads: two views (views_per_step 1 + a labelled one) of the largest size, as floats
  // (picture, mask, labels) and their 8 / 8 / 16-bit host copies.
  EXPECT_EQ(e.views, on_device + 2 * 12 * 8 * (12 + 4 + 8 + 1 + 1 + 2));
}

TEST(MemoryEstimate, GaussiansGrowFromThePointsUpToTheCap) {
  const io::Scene scene = mixedScene();
  gaussians::TrainConfig config;
  gaussians::MemoryEstimate e = gaussians::estimateTrainingMemory(scene, config);
  EXPECT_EQ(e.peak_gaussians, static_cast<std::int64_t>(10 * gaussians::kPeakGaussiansPerPoint));
  EXPECT_EQ(e.gaussians, e.peak_gaussians * gaussians::bytesPerGaussian(config));
  config.max_gaussians = 25;
  e = gaussians::estimateTrainingMemory(scene, config);
  EXPECT_EQ(e.peak_gaussians, 25);
  // Each Gaussian's learnable floats are held four times (value, gradient, two moments): one
  // more feature channel costs at least 16 bytes.
  gaussians::TrainConfig wider = config;
  wider.feature_dim += 1;
  EXPECT_GE(gaussians::bytesPerGaussian(wider) - gaussians::bytesPerGaussian(config), 16);
  // A CUDA device adds its context; the total is the parts with the allocator's slack.
  config.device = gaussians::TrainDevice::kCuda;
  e = gaussians::estimateTrainingMemory(scene, config);
  EXPECT_EQ(e.fixed, gaussians::kFixedDeviceBytes);
  EXPECT_GE(e.total(), e.fixed + e.views + e.gaussians + e.render);
}

}  // namespace
}  // namespace sadsplat
