#include "training_views.h"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <thread>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/counter_random.h"
#include "sadsplat/io/scene_cache.h"

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
  HostView host;
  if (loader) {
    host = loader->take(v);
  } else {
    host.image = images[v];
    host.mask = masks[v];
    host.labels = labels[v];
  }
  // The conversions of loadTrainingViews, on the device: the same values.
  DeviceView d;
  d.image = host.image.to(device, /*non_blocking=*/true).to(at::kFloat).div(255.0);
  d.mask = host.mask.to(device, /*non_blocking=*/true).to(at::kFloat).div(255.0);
  if (host.labels.defined()) d.labels = host.labels.to(device, /*non_blocking=*/true).to(at::kLong);
  return d;
}

void TrainingViews::prefetch(const TrainConfig& config, int it, int rank, int ranks) {
  if (!loader) return;
  for (int k = std::max(prefetched_until + 1, it); k <= it + kPrefetchSteps; ++k) {
    for (int v : drawStepViews(*this, config, k, rank, ranks, false).views) loader->request(v, k);
  }
  prefetched_until = std::max(prefetched_until, it + kPrefetchSteps);
  loader->forgetBefore(it);
}

std::vector<RasterCamera> TrainingViews::trainingCameras() const {
  std::vector<RasterCamera> training;
  for (int v : train_views) training.push_back(cameras[v]);
  return training;
}

ViewRole TrainingViews::role(int v, const TrainConfig& config) const {
  ViewRole r;
  r.semantic = supervised[v] && semantic_weight[v] > 0 && config.feature_dim > 0;
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

namespace {

// View `v` (holding its pixels) as host tensors; with `summaries` also the confidence map and
// flags the trainer keeps of it.
HostView hostView(const io::View& v, const TrainConfig& config, bool pin, bool summaries) {
  const int H = v.camera.height, W = v.camera.width;
  // A host copy the device can read asynchronously: page-locked for a CUDA device.
  const auto host = [&](const at::Tensor& t) { return pin ? t.pin_memory() : t.clone(); };
  HostView h;
  const at::Tensor rgb8 = at::from_blob(const_cast<std::uint8_t*>(v.rgb.pixels.data()), {H, W, 3},
                                        at::TensorOptions().dtype(at::kByte));
  const at::Tensor mask8 = at::from_blob(const_cast<std::uint8_t*>(v.mask.pixels.data()), {H, W},
                                         at::TensorOptions().dtype(at::kByte));
  h.image = host(rgb8);
  h.mask = host(mask8);
  // Semantic supervision (ground truth wins, then kept pseudo-labels).
  h.ground_truth = v.labelled && !v.labels.empty();
  const std::vector<std::int16_t> sup = io::supervisionLabels(v, config.use_pseudo_labels);
  if (std::any_of(sup.begin(), sup.end(), [](std::int16_t l) { return l >= 0; })) {
    h.labels = host(at::from_blob(const_cast<std::int16_t*>(sup.data()), {H, W},
                                  at::TensorOptions().dtype(at::kShort)));
  }
  if (!summaries) return h;
  h.mask_is_full = std::all_of(v.mask.pixels.begin(), v.mask.pixels.end(),
                               [](std::uint8_t m) { return m == 255; });
  // The confidence map of the drop: 1 on ground-truth pixels, else the pseudo-label backend's
  // max class score.
  if (!v.pseudo.empty()) {
    const std::vector<float> best = v.pseudo.maxScoreMap();
    h.confidence = at::from_blob(const_cast<float*>(best.data()), {H, W}, at::kFloat).clone();
  }
  if (h.ground_truth) {
    const at::Tensor gt_valid =
        (at::from_blob(const_cast<std::uint8_t*>(v.labels.pixels.data()), {H, W},
                       at::TensorOptions().dtype(at::kByte)) != io::kIgnoreLabel) &
        (mask8.to(at::kFloat).div(255.0) >= 0.5);
    h.confidence = at::where(gt_valid, at::ones({H, W}),
                             h.confidence.defined() ? h.confidence : at::zeros({H, W}));
  }
  return h;
}

// Every core but the one that drives the training, at most 16: a 1600x900 view takes ~70 ms to
// read and decode on one core, and a GPU step ~7 ms.
int loaderThreads() {
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(cores - 1, 1, 16);
}

}  // namespace

TrainingViews cameraViews(const io::Scene& scene, const at::Device& device) {
  TrainingViews s;
  s.device = device;
  s.cameras_only = true;
  const std::size_t n = scene.views.size();
  for (std::size_t i = 0; i < n; ++i) {
    s.cameras.push_back(RasterCamera::fromPinhole(scene.views[i].camera));
    if (scene.views[i].train) s.train_views.push_back(static_cast<int>(i));
  }
  s.images.resize(n);
  s.masks.resize(n);
  s.mask_is_full.assign(n, 0);
  s.labels.resize(n);
  s.supervised.assign(n, 0);
  s.semantic_weight.assign(n, 0.0);
  s.confidence_maps.resize(n);
  if (s.train_views.empty()) {
    throw Error(scene.source, "split", "at least one training view", "none");
  }
  return s;
}

TrainingViews loadTrainingViews(const io::Scene& scene, const TrainConfig& config,
                                const at::Device& device) {
  TrainingViews s;
  s.device = device;
  const bool pin = device.is_cuda() && config.stream_views;
  // Views whose pixels wait in a scene cache are read on loader threads, a window at a time;
  // streamed, they are read again for each step that uses them.
  std::vector<io::View> waiting(scene.views.size());
  bool from_cache = false;
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    if (!scene.views[i].train || !scene.views[i].pixels_in_cache) continue;
    waiting[i] = scene.views[i];
    from_cache = true;
  }
  s.streamed = config.stream_views;
  // The first read keeps only the summaries of a streamed view (no page-locked copies); the
  // loader of the steps only the pictures.
  const auto loaderFor = [&](bool summaries) {
    const bool pin_copies = pin && !summaries;
    return std::make_shared<ViewLoader>(
        [waiting, config, pin_copies, summaries](int v) {
          return hostView(io::readViewPixels(waiting[v]), config, pin_copies, summaries);
        },
        loaderThreads());
  };
  std::shared_ptr<ViewLoader> first_read;
  std::vector<int> order;  // the training views, for the first read's window
  for (std::size_t i = 0; i < scene.views.size(); ++i)
    if (scene.views[i].train) order.push_back(static_cast<int>(i));
  if (from_cache) first_read = loaderFor(true);
  const int window = 2 * loaderThreads();
  std::size_t next = 0;
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const io::View& v = scene.views[i];
    s.cameras.push_back(RasterCamera::fromPinhole(v.camera));
    if (!v.train) {
      s.images.emplace_back();
      s.masks.emplace_back();
      s.mask_is_full.push_back(0);
      s.labels.emplace_back();
      s.supervised.push_back(0);
      s.semantic_weight.push_back(0.0);
      s.confidence_maps.emplace_back();
      continue;
    }
    HostView h;
    if (v.pixels_in_cache) {
      for (; next < order.size() && order[next] < static_cast<int>(i) + window; ++next)
        first_read->request(order[next], order[next]);
      h = first_read->take(static_cast<int>(i));
      first_read->forgetBefore(static_cast<int>(i) + 1);
    } else {
      h = hostView(v, config, pin, true);
    }
    if (h.labels.defined()) {
      if (h.ground_truth) {
        s.labelled_views.push_back(static_cast<int>(i));
      } else {
        ++s.pseudo_labelled_views;
      }
    }
    s.mask_is_full.push_back(h.mask_is_full);
    s.supervised.push_back(h.labels.defined());
    s.semantic_weight.push_back(h.ground_truth ? config.lambda_semantic : config.lambda_pseudo);
    s.confidence_maps.push_back(h.confidence.defined() ? h.confidence.to(device) : h.confidence);
    if (s.streamed && v.pixels_in_cache) {  // read again for each step
      s.images.emplace_back();
      s.masks.emplace_back();
      s.labels.emplace_back();
    } else if (s.streamed) {
      s.images.push_back(h.image);
      s.masks.push_back(h.mask);
      s.labels.push_back(h.labels);
    } else {
      s.images.push_back(h.image.to(at::kFloat).div(255.0).to(device));
      s.masks.push_back(h.mask.to(at::kFloat).div(255.0).to(device));
      s.labels.push_back(h.labels.defined() ? h.labels.to(at::kLong).to(device) : h.labels);
    }
    s.train_views.push_back(static_cast<int>(i));
  }
  if (s.train_views.empty()) {
    throw Error(scene.source, "split", "at least one training view", "none");
  }
  if (s.streamed && from_cache) s.loader = loaderFor(false);
  return s;
}

std::int64_t addSparseDepths(const io::Scene& scene, TrainingViews& views) {
  views.sparse_depths.assign(views.cameras.size(), SparseDepthSamples());
  const at::Tensor points = sparsePointTensor(scene);
  if (!points.defined()) return 0;
  std::int64_t total = 0;
  for (int v : views.train_views) {
    SparseDepthSamples s = visibleSparseDepths(points, views.cameras[v]);
    total += s.size();
    s.pixels = s.pixels.to(views.device);
    s.depths = s.depths.to(views.device);
    views.sparse_depths[v] = std::move(s);
  }
  return total;
}

}  // namespace gaussians
}  // namespace sadsplat
