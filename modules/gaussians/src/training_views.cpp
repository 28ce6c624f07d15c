#include "training_views.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/counter_random.h"

namespace sadsplat {
namespace gaussians {

std::vector<int> TrainingViews::guardProbeViews() const {
  const std::size_t n = train_views.size();
  const std::size_t k = std::min<std::size_t>(n, kGuardProbeViews);
  std::vector<int> probe;
  for (std::size_t i = 0; i < k; ++i) probe.push_back(train_views[i * n / k]);
  return probe;
}

DeviceView TrainingViews::onDevice(int v) const {
  if (!streamed) return {images[v], masks[v], labels[v]};
  // The conversions of loadTrainingViews, on the device: the same values.
  DeviceView d;
  d.image = images[v].to(device, /*non_blocking=*/true).to(at::kFloat).div(255.0);
  d.mask = masks[v].to(device, /*non_blocking=*/true).to(at::kFloat).div(255.0);
  if (labels[v].defined()) d.labels = labels[v].to(device, /*non_blocking=*/true).to(at::kLong);
  return d;
}

std::vector<RasterCamera> TrainingViews::trainingCameras() const {
  std::vector<RasterCamera> training;
  for (int v : train_views) training.push_back(cameras[v]);
  return training;
}

ViewRole TrainingViews::role(int v, const TrainConfig& config) const {
  ViewRole r;
  r.semantic = labels[v].defined() && semantic_weight[v] > 0 && config.feature_dim > 0;
  // Ground truth always trains the decoder; pseudo-labels when the configuration says so.
  const bool ground_truth =
      std::find(labelled_views.begin(), labelled_views.end(), v) != labelled_views.end();
  r.decoder_learns = r.semantic && (ground_truth || config.pseudo_labels_train_decoder);
  return r;
}

namespace {

// The view of a draw: the next one of a seeded shuffle of `views` (an epoch per pass).
int pickView(const std::vector<int>& views, std::uint64_t seed, RandomPurpose purpose,
             int counter) {
  const int n = static_cast<int>(views.size());
  const int epoch = counter / n, pos = counter % n;
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::vector<std::uint64_t> keys(n);
  for (int i = 0; i < n; ++i) {
    keys[i] = mixBits(seed ^ mixBits(purposeKey(purpose) ^ mixBits(epoch * 1000003ull + i)));
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return keys[a] < keys[b]; });
  return views[order[pos]];
}

}  // namespace

StepViews drawStepViews(const TrainingViews& s, const TrainConfig& c, int it, int rank, int ranks,
                        bool in_group) {
  const int batch = c.views_per_step * ranks;
  const bool semantic_step = !s.labelled_views.empty() && c.semantic_interval > 0 &&
                             c.lambda_semantic > 0 && it % c.semantic_interval == 0;
  // The views of one draw: a training view, on semantic steps also a labelled one.
  auto drawViews = [&](int draw, std::vector<int>* views) {
    const int tv = pickView(s.train_views, c.seed, RandomPurpose::kTrainingView, it * batch + draw);
    views->push_back(tv);
    if (semantic_step) {
      const int lv = pickView(s.labelled_views, c.seed, RandomPurpose::kLabelledView,
                              (it / c.semantic_interval) * batch + draw);
      if (lv != tv) views->push_back(lv);
    }
  };
  StepViews step;
  for (int b = 0; b < c.views_per_step; ++b) drawViews(rank * c.views_per_step + b, &step.views);
  if (in_group) {
    std::vector<int> all;
    for (int draw = 0; draw < batch; ++draw) drawViews(draw, &all);
    for (int v : all) {
      step.features_anywhere = step.features_anywhere || s.role(v, c).semantic;
      step.decoder_anywhere = step.decoder_anywhere || s.role(v, c).decoder_learns;
    }
  }
  return step;
}

TrainingViews loadTrainingViews(const io::Scene& scene, const TrainConfig& config,
                                const at::Device& device) {
  TrainingViews s;
  s.streamed = config.stream_views;
  s.device = device;
  // A host copy the device can read asynchronously: page-locked for a CUDA device.
  const auto host = [&](const at::Tensor& t) {
    return device.is_cuda() ? t.pin_memory() : t.clone();
  };
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const io::View& v = scene.views[i];
    s.cameras.push_back(RasterCamera::fromPinhole(v.camera));
    if (!v.train) {
      s.images.emplace_back();
      s.masks.emplace_back();
      s.mask_is_full.push_back(0);
      s.labels.emplace_back();
      s.semantic_weight.push_back(0.0);
      s.confidence_maps.emplace_back();
      continue;
    }
    const int H = v.camera.height, W = v.camera.width;
    const at::Tensor rgb8 = at::from_blob(const_cast<std::uint8_t*>(v.rgb.pixels.data()),
                                          {H, W, 3}, at::TensorOptions().dtype(at::kByte));
    const at::Tensor mask8 = at::from_blob(const_cast<std::uint8_t*>(v.mask.pixels.data()),
                                           {H, W}, at::TensorOptions().dtype(at::kByte));
    const at::Tensor mask = mask8.to(at::kFloat).div(255.0);
    s.images.push_back(s.streamed ? host(rgb8) : rgb8.to(at::kFloat).div(255.0).to(device));
    s.masks.push_back(s.streamed ? host(mask8) : mask.to(device));
    s.mask_is_full.push_back(std::all_of(v.mask.pixels.begin(), v.mask.pixels.end(),
                                         [](std::uint8_t m) { return m == 255; }));
    // Semantic supervision (ground truth wins, then kept pseudo-labels) and the confidence map
    // of the drop (1 on ground-truth pixels, else the pseudo-label backend's max class score).
    at::Tensor labels, confidence;
    const bool gt = v.labelled && !v.labels.empty();
    const std::vector<std::int16_t> sup = io::supervisionLabels(v, config.use_pseudo_labels);
    if (std::any_of(sup.begin(), sup.end(), [](std::int16_t l) { return l >= 0; })) {
      labels = at::from_blob(const_cast<std::int16_t*>(sup.data()), {H, W},
                             at::TensorOptions().dtype(at::kShort));
      labels = s.streamed ? host(labels) : labels.to(at::kLong);
      if (gt) {
        s.labelled_views.push_back(static_cast<int>(i));
      } else {
        ++s.pseudo_labelled_views;
      }
    }
    if (!v.pseudo.empty()) {
      const std::vector<float> best = v.pseudo.maxScoreMap();
      confidence = at::from_blob(const_cast<float*>(best.data()), {H, W}, at::kFloat).clone();
    }
    if (gt) {
      const at::Tensor gt_valid =
          (at::from_blob(const_cast<std::uint8_t*>(v.labels.pixels.data()), {H, W},
                         at::TensorOptions().dtype(at::kByte)) != io::kIgnoreLabel) &
          (mask >= 0.5);
      confidence = at::where(gt_valid, at::ones({H, W}),
                             confidence.defined() ? confidence : at::zeros({H, W}));
    }
    s.labels.push_back(labels.defined() && !s.streamed ? labels.to(device) : labels);
    s.semantic_weight.push_back(gt ? config.lambda_semantic : config.lambda_pseudo);
    s.confidence_maps.push_back(confidence.defined() ? confidence.to(device) : confidence);
    s.train_views.push_back(static_cast<int>(i));
  }
  if (s.train_views.empty()) {
    throw Error(scene.source, "split", "at least one training view", "none");
  }
  return s;
}

}  // namespace gaussians
}  // namespace sadsplat
