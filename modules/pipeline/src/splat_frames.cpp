#include "sadsplat/pipeline/splat_frames.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/gaussian_tensors.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/gaussians/device.h"

namespace sadsplat {
namespace pipeline {

struct SplatFrames::State {
  at::Device device{at::kCPU};
  std::unique_ptr<OpenedRun> run;        // a run: its trainer renders and decodes
  pcl::PointCloud<GaussianPoint> cloud;  // the Gaussians, in the order the tensors hold them
  gaussians::GaussianParams params;      // render-ready (runs: the trainer's parameters)
  int sh_degree = 3;
  int num_labels = 0;  // plain models: 1 + the largest label

  at::Tensor keepMask(const io::FrameRequest& r) const {
    if (!r.visible) return at::Tensor();
    std::vector<std::uint8_t> keep(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) keep[i] = r.visible(cloud[i].label) ? 1 : 0;
    return at::from_blob(keep.data(), {static_cast<std::int64_t>(keep.size())}, at::kByte)
        .to(device, at::kFloat);
  }

  // Renders `params` with per-Gaussian features (C channels) instead of the model's.
  gaussians::RenderResult renderFeatures(const gaussians::RasterCamera& cam, const at::Tensor& keep,
                                         const at::Tensor& features) const {
    gaussians::GaussianParams g = params;
    g.features = features;
    g.opacity_gate = keep;  // undefined: every Gaussian
    gaussians::RenderSettings settings;
    settings.sh_degree = 0;
    settings.depth = false;
    return gaussians::render(g, cam, settings);
  }
};

SplatFrames::SplatFrames(const std::string& path, const std::string& device) : state_(new State) {
  State& s = *state_;
  s.device = gaussians::deviceNamed(device, path);
  if (io::RunDirectory::hasCheckpoint(path)) {
    s.run = std::make_unique<OpenedRun>(openRun(path));
    s.cloud = labelledCloud(*s.run->trainer, s.run->scene);
    s.params = s.run->trainer->parameters();
    return;
  }
  const std::string model = io::isDirectory(path) ? io::RunDirectory(path).model() : path;
  s.cloud = io::readGaussians(model);
  const gaussians::GaussianTensors t = gaussians::fromCloud(s.cloud, s.device, /*feature_dim=*/0);
  s.params.means = t.means;
  s.params.quats = t.rotations;
  s.params.log_scales = t.log_scales;
  s.params.opacity_logits = t.opacity_logit;
  s.params.sh = t.sh_dc;
  s.params.sh_rest = t.sh_rest;
  for (const auto& p : s.cloud) {
    if (p.label != kUnlabelled) s.num_labels = std::max<int>(s.num_labels, p.label + 1);
  }
  s.num_labels = std::min(s.num_labels, 256);
}

SplatFrames::~SplatFrames() = default;

bool SplatFrames::decodesClasses() const { return state_->run != nullptr; }

io::SplatFrame SplatFrames::render(const io::FrameRequest& request) const {
  const State& s = *state_;
  const gaussians::RasterCamera cam = gaussians::RasterCamera::fromPinhole(request.camera);
  const at::Tensor keep = s.keepMask(request);
  io::SplatFrame frame;
  frame.width = cam.width;
  frame.height = cam.height;
  const std::size_t n = static_cast<std::size_t>(cam.width) * cam.height;
  auto take_alpha = [&](const gaussians::RenderResult& r) {
    const at::Tensor a = r.alpha.to(at::kCPU, at::kFloat).contiguous();
    frame.alpha.assign(a.data_ptr<float>(), a.data_ptr<float>() + n);
  };
  const auto N = static_cast<std::int64_t>(s.cloud.size());
  if (request.content == io::FrameContent::kScalar) {
    std::vector<float> values(s.cloud.size(), 0.f);
    if (request.scalar) {
      for (std::size_t i = 0; i < s.cloud.size(); ++i) values[i] = request.scalar(s.cloud[i]);
    }
    const at::Tensor f = at::from_blob(values.data(), {N, 1}, at::kFloat).to(s.device);
    const gaussians::RenderResult r = s.renderFeatures(cam, keep, f);
    take_alpha(r);
    const at::Tensor v = (r.features.select(2, 0) / r.alpha.clamp_min(1e-6))
                             .clamp(0, 1)
                             .to(at::kCPU, at::kFloat)
                             .contiguous();
    frame.scalar.assign(v.data_ptr<float>(), v.data_ptr<float>() + n);
    for (std::size_t i = 0; i < n; ++i) {
      if (frame.alpha[i] <= 0.f) frame.scalar[i] = 0.f;
    }
    return frame;
  }
  gaussians::RenderResult r;
  at::Tensor classes;  // [H, W] int64
  if (s.run) {
    r = s.run->trainer->renderCamera(cam, keep);
    if (request.content == io::FrameContent::kClasses) {
      const at::Tensor cosines = s.run->trainer->classCosines(r);
      if (!cosines.defined()) {
        throw Error(s.run->dir, "classes", "a model with a class list (--color rgb shows it)",
                    "an RGB-only run");
      }
      classes = std::get<1>(cosines.max(2));
    }
  } else if (request.content == io::FrameContent::kClasses) {
    // One channel per label and one for "unlabelled": the argmax of the blended one-hot labels.
    const int C = s.num_labels + 1;
    std::vector<float> onehot(static_cast<std::size_t>(N) * C, 0.f);
    for (std::int64_t i = 0; i < N; ++i) {
      const std::uint32_t l = s.cloud[i].label;
      onehot[i * C + (l < static_cast<std::uint32_t>(s.num_labels) ? l : C - 1)] = 1.f;
    }
    const at::Tensor f = at::from_blob(onehot.data(), {N, C}, at::kFloat).to(s.device);
    r = s.renderFeatures(cam, keep, f);
    classes = std::get<1>(r.features.max(2));
    classes = at::where(classes == C - 1, at::full_like(classes, -2), classes);
  } else {
    gaussians::GaussianParams g = s.params;
    if (keep.defined()) g.opacity_gate = keep;
    gaussians::RenderSettings settings;
    settings.sh_degree = s.sh_degree;
    settings.features = false;
    settings.depth = false;
    r = gaussians::render(g, cam, settings);
  }
  take_alpha(r);
  if (request.content == io::FrameContent::kClasses) {
    const at::Tensor c = classes.to(at::kCPU, at::kLong).contiguous();
    const std::int64_t* pc = c.data_ptr<std::int64_t>();
    frame.classes.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      frame.classes[i] = frame.alpha[i] < 0.5f ? -1 : static_cast<std::int16_t>(pc[i]);
    }
  } else {
    const at::Tensor rgb = r.rgb.clamp(0, 1).mul(255).round().to(at::kCPU, at::kByte).contiguous();
    frame.rgb.assign(rgb.data_ptr<std::uint8_t>(), rgb.data_ptr<std::uint8_t>() + 3 * n);
  }
  return frame;
}

}  // namespace pipeline
}  // namespace sadsplat
