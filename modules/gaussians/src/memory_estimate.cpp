#include "sadsplat/gaussians/memory_estimate.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "sadsplat/gaussians/initialization.h"

namespace sadsplat {
namespace gaussians {

namespace {

// Per pixel of a rendered view, in floats: the forward's colour (3), alpha, depth, transmittance
// and last-contributor index (4) and features (feature_dim); the gradients of colour and
// features; the photometric loss's SSIM (five blurred images of three channels, forward and
// backward) and the L1 / semantic terms (~10).
std::int64_t renderFloatsPerPixel(const TrainConfig& c) {
  return 3 + 4 + c.feature_dim + 3 + c.feature_dim + 2 * 5 * 3 + 10;
}

bool supervised(const io::View& v, const TrainConfig& c) {
  if (v.labelled && v.hasLabels()) return true;
  return c.use_pseudo_labels && v.hasPseudoLabels();
}

bool hasConfidence(const io::View& v) {
  return (v.labelled && v.hasLabels()) || v.hasPseudoLabels();
}

}  // namespace

std::int64_t MemoryEstimate::total() const {
  return static_cast<std::int64_t>(
      std::ceil(static_cast<double>(fixed + views + gaussians + render) * kAllocatorSlack));
}

std::string MemoryEstimate::describe() const {
  const auto gib = [](std::int64_t bytes) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(2) << static_cast<double>(bytes) / (1ll << 30);
    return text.str();
  };
  return gib(total()) + " GiB estimated (views " + gib(views) + ", " +
         std::to_string(peak_gaussians) + " Gaussians at the peak " + gib(gaussians) +
         ", render " + gib(render) + ", fixed " + gib(fixed) + ")";
}

std::int64_t bytesPerGaussian(const TrainConfig& c) {
  const std::int64_t sh = 3ll * (c.max_sh_degree + 1) * (c.max_sh_degree + 1);
  const std::int64_t learnable = 3 + 3 + 4 + 1 + sh + c.feature_dim + 1;
  // Projected centre (2), conic (3), colour (3), depth, radius (2), opacity and the features a
  // render carries, each with a gradient.
  const std::int64_t rendered = 2 * (2 + 3 + 3 + 1 + 2 + 1 + c.feature_dim);
  const std::int64_t statistics = 4;
  const std::int64_t tile_entries = 16 * 4;  // ~16 tiles a Gaussian, key + value, sort buffers
  return 4 * (4 * learnable + rendered + statistics + tile_entries);
}

MemoryEstimate estimateTrainingMemory(const io::Scene& scene, const std::vector<int>& views,
                                      std::size_t points, const TrainConfig& c) {
  MemoryEstimate e;
  e.fixed = c.device == TrainDevice::kCuda ? kFixedDeviceBytes : 0;
  std::int64_t largest = 0;
  for (int i : views) {
    const io::View& v = scene.views.at(static_cast<std::size_t>(i));
    const std::int64_t pixels = static_cast<std::int64_t>(v.camera.width) * v.camera.height;
    largest = std::max(largest, pixels);
    const std::int64_t confidence = hasConfidence(v) ? 4 : 0;
    const std::int64_t labels = supervised(v, c) ? 8 : 0;
    e.views += pixels * (c.stream_views ? confidence : 12 + 4 + labels + confidence);
  }
  // A step renders views_per_step views, and one labelled view more on semantic steps.
  const std::int64_t per_step = c.views_per_step + 1;
  if (c.stream_views) e.views += per_step * largest * (12 + 4 + 8 + 1 + 1 + 2);
  e.render = per_step * largest * 4 * renderFloatsPerPixel(c);
  const double grown = std::ceil(kPeakGaussiansPerPoint * static_cast<double>(points));
  e.peak_gaussians = static_cast<std::int64_t>(
      std::min<double>(std::max<double>(grown, static_cast<double>(points)), c.max_gaussians));
  e.gaussians = e.peak_gaussians * bytesPerGaussian(c);
  return e;
}

MemoryEstimate estimateTrainingMemory(const io::Scene& scene, const TrainConfig& c) {
  std::vector<int> views;
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    if (scene.views[i].train) views.push_back(static_cast<int>(i));
  }
  const std::size_t points = initialisesRandomly(c.init, scene.points.size())
                                 ? static_cast<std::size_t>(c.init_random_count)
                                 : scene.points.size();
  return estimateTrainingMemory(scene, views, points, c);
}

}  // namespace gaussians
}  // namespace sadsplat
