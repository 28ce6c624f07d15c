#include "sadsplat/gaussians/trainer.h"

#include <ATen/CPUGeneratorImpl.h>
#include <c10/core/GradMode.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <tuple>
#include <utility>

#include "drop_state.h"
#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/contribution.h"
#include "sadsplat/gaussians/counter_random.h"
#include "sadsplat/gaussians/densification.h"
#include "sadsplat/gaussians/device.h"
#include "sadsplat/gaussians/gaussian_tensors.h"
#include "sadsplat/gaussians/image_metrics.h"
#include "sadsplat/gaussians/initialization.h"
#include "sadsplat/gaussians/parameter_store.h"
#include "sadsplat/gaussians/schedule.h"
#include "sadsplat/gaussians/semantic_loss.h"
#include "sadsplat/gaussians/sparse_depth_loss.h"
#include "sadsplat/gaussians/tensor_archive.h"
#include "sadsplat/gaussians/tile_list_capacity.h"
#include "sadsplat/gaussians/view_coverage.h"
#include "sadsplat/io/gaussian_checks.h"
#include "training_views.h"

namespace sadsplat {
namespace gaussians {

namespace {

// Every log-scale stays within e^+-20 of the scene extent, and within what the model's writer and
// readers accept (io::kMaxAbsLogScale): Adam keeps shrinking a Gaussian whose gradient keeps one
// sign, and over a 30k schedule log-scales reached -51.7 (the writer then refused the model).
// e^-20 of the extent is far below a pixel of any view, so the bound changes no image. A
// projection after the optimiser step (Adam's moments stay as they are).
void holdLogScalesNearExtent(at::Tensor& log_scales, double extent) {
  constexpr double kSpan = 20.0;
  const double log_extent = std::log(extent);
  log_scales.clamp_(std::max(log_extent - kSpan, 1.0 - io::kMaxAbsLogScale),
                    std::min(log_extent + kSpan, io::kMaxAbsLogScale - 1.0));
}

// What one step's passes share: its views, render settings and Gaussians, the losses and the
// renders that the densification statistics read.
struct StepPass {
  std::vector<int> views;
  int ranks = 1;
  int batch = 1;
  bool read_losses = false;
  RenderSettings settings;
  GaussianParams g;
  at::Tensor total, rgb_sum, sem_sum;
  std::vector<RenderResult> renders;
  std::vector<RasterCamera> cameras;
};

}  // namespace

// The trainer composes the units that do the work (gsplat's shape): the parameters with their
// Adam moments (parameter_store.h), the densification strategy (densification.h), the drop's
// state over the schedule (drop_state.h) and the views (training_views.h); step() reads as views
// -> render -> losses -> backward -> statistics -> optimiser -> drop -> densification.
struct Trainer::State {
  // The drop state sees the schedule as the trainer runs it (its guard needs the opacity resets).
  explicit State(const TrainConfig& c) : config(resolveDerivedKeys(c)), drop(config, config) {}

  TrainConfig config;
  at::Device device{at::kCPU};
  int iteration = 0;
  double extent = 1;
  int num_classes = 0;
  TrainingViews views;
  // Parameters: means, sh_dc, sh_rest, opacity, scales, quats, features, log_alpha; decoder W, b.
  ParameterStore params;
  DropState drop;
  DensificationStrategy::Ptr densification;
  StepProfile::Ptr profile;
  Collective::Ptr collective;
  // CUDA: the training renders' tile lists are sized from earlier renders (no wait per render).
  std::unique_ptr<TileListCapacity> tile_capacity;

  // The one way the Gaussians' rows change: every per-row state follows the parameters.
  void resize(const at::Tensor& keep, const std::map<std::string, at::Tensor>& extra) {
    const RowChange change = params.resize(keep, extra);
    drop.resized(change);
    densification->resized(change);
  }
  DensificationStrategy::Resize resizer() {
    return [this](const at::Tensor& keep, const std::map<std::string, at::Tensor>& extra) {
      resize(keep, extra);
    };
  }

  int shDegree() const {
    return std::min(config.max_sh_degree, iteration / std::max(1, config.sh_increase_interval));
  }

  // The model as evaluation renders it: deterministic gates, the SH degree reached so far.
  GaussianParams evaluationGaussians() const {
    GaussianParams g = params.gaussians();
    g.opacity_gate = drop.evaluationGate(params, iteration);
    return g;
  }
  // The same, drawing only the Gaussians where `keep` ([N] bool, any device) is true (undefined:
  // all of them).
  GaussianParams evaluationGaussians(const at::Tensor& keep) const {
    GaussianParams g = evaluationGaussians();
    if (!keep.defined()) return g;
    if (keep.dim() != 1 || keep.size(0) != g.means.size(0)) {
      throw Error("<render>", "keep mask",
                  "one flag per Gaussian (" + std::to_string(g.means.size(0)) + ")",
                  std::to_string(keep.numel()));
    }
    const at::Tensor k = keep.to(g.means.device(), g.means.scalar_type());
    g.opacity_gate = g.opacity_gate.defined() ? g.opacity_gate * k : k;
    return g;
  }
  RenderSettings evaluationSettings() const {
    RenderSettings settings;
    settings.sh_degree = shDegree();
    settings.background = config.background;
    return settings;
  }

  // The mean squared error of the drop guard's probe views, rendered as evaluation renders them
  // (deterministic gates, no features). Every rank renders the same views of the same model; the
  // mean over the ranks makes their guards agree to the bit, so their drop events stay alike.
  double guardProbeError() const {
    c10::AutoGradMode no_grad(false);
    RenderSettings settings = evaluationSettings();
    settings.features = false;
    settings.depth = false;
    const GaussianParams g = evaluationGaussians();
    const std::vector<int> probe = views.guardProbeViews();
    if (probe.empty()) return std::numeric_limits<double>::quiet_NaN();
    at::Tensor sum;
    for (int v : probe) {
      const at::Tensor rgb = render(g, views.cameras[v], settings).rgb.clamp(0, 1);
      const DeviceView view = views.onDevice(v);
      const at::Tensor mask = view.mask.unsqueeze(2);
      const at::Tensor mse =
          ((rgb - view.image).square() * mask).sum() / (3 * mask.sum()).clamp_min(1);
      sum = sum.defined() ? sum + mse : mse;
    }
    at::Tensor mean = (sum / static_cast<double>(probe.size())).reshape({1}).contiguous();
    if (collective) {
      collective->sum(mean);
      mean = mean / collective->size();
    }
    return mean.item<double>();
  }

  at::Tensor decode(const at::Tensor& features) const {
    return at::linear(features, params["decoder_w"].value, params["decoder_b"].value);
  }

  // The parts of Trainer::step, in its order (views -> render -> losses -> backward ->
  // statistics -> optimiser -> drop -> densification).
  void renderLossesBackward(StepPass& pass, int it, TileListCapacity* tile_capacity);
  at::Tensor viewLoss(StepPass& pass, int v);
  void reduceAndUpdate(const StepPass& pass, const StepViews& step_views, int it);
  void afterUpdate(int done, bool gated, StepStats& stats);
  void readLossValues(const StepPass& pass, StepStats& stats) const;
};

// The step's renders, losses and backward pass; again (the same gates: counter-based noise) when
// a render's tile list was short.
void Trainer::State::renderLossesBackward(StepPass& pass, int it, TileListCapacity* tile_capacity) {
  const TrainConfig& c = config;
  pass.total = pass.rgb_sum = pass.sem_sum = at::Tensor();
  pass.renders.clear();
  pass.cameras.clear();
  pass.settings.tile_capacity = tile_capacity;
  // Counter-based noise: a second pass samples the same gates (the first one's graph is gone).
  pass.g.opacity_gate = drop.trainingGate(params, it);  // undefined when not gated
  for (int v : pass.views) {
    const at::Tensor loss = viewLoss(pass, v);
    pass.total = pass.total.defined() ? pass.total + loss : loss;
  }
  // The mean over the global batch (one draw: the sum of its training and labelled views'
  // losses).
  if (pass.batch > 1) pass.total = pass.total / pass.batch;
  const at::Tensor reg = drop.regularisation(params, it);
  if (reg.defined()) {
    pass.total = pass.total + (pass.ranks > 1 ? reg / pass.ranks : reg);  // once over all ranks
  }
  if (c.lambda_flatten > 0) {
    const at::Tensor flat = std::get<0>(params["scales"].value.exp().min(1)).mean() *
                            (c.lambda_flatten / extent / pass.ranks);
    pass.total = pass.total + flat;
  }
  enterPhase(profile.get(), "backward");
  pass.total.backward();
}

// One view's render and loss (RGB, and the semantic loss where the view's role asks for it).
at::Tensor Trainer::State::viewLoss(StepPass& pass, int v) {
  const TrainConfig& c = config;
  StepProfile* p = profile.get();
  // Loss values stay on the device until the end of the step: one host synchronisation per step.
  const auto accumulate = [&pass](at::Tensor& sum, const at::Tensor& value) {
    if (!pass.read_losses) return;  // nobody reads them: two operations per render saved
    sum = sum.defined() ? sum + value.detach() : value.detach();
  };
  enterPhase(p, "render forward");
  const ViewRole role = views.role(v, c);
  // Features only where a semantic loss reads them, depth only for the sparse-depth loss.
  const bool sparse_depth = c.lambda_sparse_depth > 0 && !views.sparse_depths.empty() &&
                            views.sparse_depths[v].size() > 0;
  pass.settings.features = role.semantic;
  pass.settings.depth = sparse_depth;
  RenderResult r = render(pass.g, views.cameras[v], pass.settings);
  r.means2d.retain_grad();
  enterPhase(p, "losses forward");
  // Factors of exactly 1 (a full mask, unit weights) are left out: the same values, fewer
  // operations for the host to issue and for the autograd engine to run backwards.
  const DeviceView view = views.onDevice(v);
  const at::Tensor& gt = view.image;
  const bool masked = !views.mask_is_full[v];
  const at::Tensor mask = masked ? view.mask.unsqueeze(2) : at::Tensor();
  const auto masking = [&](const at::Tensor& image) { return masked ? image * mask : image; };
  // Unmasked with the fused SSIM: rgbLoss (on CUDA one autograd node; elsewhere this very
  // composition).
  const at::Tensor rgb_loss =
      !masked && c.fused_ssim
          ? rgbLoss(r.rgb, gt, c.lambda_ssim)
          : (1 - c.lambda_ssim) * masking((r.rgb - gt).abs()).mean() +
                c.lambda_ssim * (1 - (c.fused_ssim ? ssim(masking(r.rgb), masking(gt))
                                                   : ssimReference(masking(r.rgb), masking(gt))));
  at::Tensor loss = c.lambda_rgb == 1 ? rgb_loss : c.lambda_rgb * rgb_loss;
  accumulate(pass.rgb_sum, rgb_loss);
  if (role.semantic) {
    // Paper, "Training Loss": 1 - cosine similarity to the class embedding (one-hot in the
    // class-score space of the built-in backend), averaged over supervised pixels only.
    const at::Tensor& w = params["decoder_w"].value;
    const at::Tensor& b = params["decoder_b"].value;
    const auto loss_of = c.fused_semantic_loss ? semanticLoss : semanticLossReference;
    const at::Tensor& labels = view.labels;
    const at::Tensor sem = role.decoder_learns
                               ? loss_of(r.features, labels, w, b)
                               : loss_of(r.features, labels, w.detach(), b.detach());
    const double weight = views.semantic_weight[v];
    loss = loss + (weight == 1 ? sem : weight * sem);
    accumulate(pass.sem_sum, sem);
  }
  if (sparse_depth) {
    loss = loss + c.lambda_sparse_depth * sparseDepthLoss(r.depth, views.sparse_depths[v]);
  }
  pass.renders.push_back(r);
  pass.cameras.push_back(views.cameras[v]);
  return loss;
}

// After the backward: the densification's statistics, the group's all-reduce, the balanced
// rule's L0 force, the optimiser.
void Trainer::State::reduceAndUpdate(const StepPass& pass, const StepViews& step_views, int it) {
  StepProfile* p = profile.get();
  enterPhase(p, "densification statistics");
  const std::vector<at::Tensor*> sums =
      densification->stepPostBackward(pass.renders, pass.cameras, pass.batch, collective.get());
  if (collective) {
    enterPhase(p, "all-reduce");
    params.allReduceGradients(
        *collective,
        [&](const Parameter& q) {
          if (q.name == "features") return step_views.features_anywhere;
          if (q.name == "decoder_w" || q.name == "decoder_b") return step_views.decoder_anywhere;
          return q.value.grad().defined();
        },
        sums);
    densification->reduced(*collective);
  }
  drop.addL0Gradient(params, it);  // the balanced rule's L0 force (else a no-op)
  enterPhase(p, "optimiser");
  params.adamStep();
  holdLogScalesNearExtent(params["scales"].value, extent);
}

// After the update of iteration `done`: the drop's guard and event, the recovery's start, the
// end-of-training removals, then densification, pruning and the opacity reset.
void Trainer::State::afterUpdate(int done, bool gated, StepStats& stats) {
  const TrainConfig& c = config;
  enterPhase(profile.get(), "drop");
  if (gated && drop.guardProbeDue(done)) drop.observeGuardProbe(done, guardProbeError());
  if (gated) stats.drop = drop.dropIfDue(done, params, views, resizer(), &stats.dropped);
  if (done == drop.recoveryStart()) {
    std::tie(stats.recovery_closed_gates, stats.recovery_pruned) =
        drop.settleGates(params, views, resizer());
  }
  if (done == c.iterations) {
    stats.removed_closed_gates = drop.removeClosedGates(params, done, resizer());
    if (c.prune_floaters) {
      // Floaters: seen by too few training views, or far larger than the scene's detail.
      const at::Tensor keep =
          floaterMask(params["means"].value, params["scales"].value, views.trainingCameras(),
                      c.floater_min_views, c.floater_max_scale * extent)
              .logical_not();
      stats.removed_floaters = params.rows() - keep.sum().item<std::int64_t>();
      if (stats.removed_floaters > 0) resize(keep, {});
    }
  }
  enterPhase(profile.get(), "densify, prune, reset");
  densification->stepPostUpdate(
      done, params, [&] { return drop.effectiveOpacity(params, done); }, resizer());
}

// The step's loss values, read to the host (summed over the group's ranks).
void Trainer::State::readLossValues(const StepPass& pass, StepStats& stats) const {
  enterPhase(profile.get(), "loss values to host");
  const at::Tensor zero = at::zeros({}, pass.total.options());
  at::Tensor values =
      at::stack({pass.total.detach(), pass.rgb_sum, pass.sem_sum.defined() ? pass.sem_sum : zero,
                 at::full({}, static_cast<double>(pass.views.size()), pass.total.options())});
  if (collective) collective->sum(values);
  values = values.to(at::kDouble).cpu();
  const double* value = values.data_ptr<double>();
  stats.rgb_loss = value[1] / value[3];
  stats.semantic_loss = value[2] / pass.batch;
  stats.loss = value[0];
}

Trainer::Trainer(const io::Scene& scene, const TrainConfig& config, TrainerViews views)
    : state_(new State(config)) {
  State& s = *state_;
  config.check();
  s.device = deviceNamed(choiceName(config.device), "<config>");
  if (s.device.is_cuda()) {
    if (!at::hasCUDA()) {
      throw Error("<config>", "device", "cpu (no CUDA device or no CUDA build here)", "cuda");
    }
    if (config.tile_list_margin > 0) {
      s.tile_capacity = std::make_unique<TileListCapacity>(config.tile_list_margin);
    }
  }
  s.num_classes = static_cast<int>(scene.classes.size());
  // A scene without classes trains plain 3DGS: no features, no decoder rows, no semantic loss.
  if (s.num_classes == 0) s.config.feature_dim = 0;
  s.views = views == TrainerViews::kLoaded ? loadTrainingViews(scene, s.config, s.device)
                                           : cameraViews(scene, s.device);
  s.extent = sceneExtent(s.views.cameras);
  if (views == TrainerViews::kLoaded && s.config.lambda_sparse_depth > 0) {
    addSparseDepths(scene, s.views);
  }

  // Initial Gaussians (3DGS initialisation, features N(0, 0.01)).
  InitOptions init;
  init.seed = config.seed;
  std::vector<io::ScenePoint> random_points;
  if (initialisesRandomly(config.init, scene.points.size())) {
    std::vector<io::PinholeCamera> cameras;
    for (const io::View& v : scene.views) {
      if (v.train) cameras.push_back(v.camera);
    }
    random_points = randomPointsInView(cameras, config.init_random_count, config.seed);
  }
  const GaussianTensors t =
      fromCloud(initialCloud(random_points.empty() ? scene.points : random_points, init), s.device,
                s.config.feature_dim);
  ParameterStore& p = s.params;
  p.add("means", t.means, config.lr_position_init * s.extent);
  p.add("sh_dc", t.sh_dc, config.lr_sh_dc);
  p.add("sh_rest", t.sh_rest, config.lr_sh_rest);
  p.add("opacity", t.opacity_logit, config.lr_opacity);
  p.add("scales", t.log_scales, config.lr_scaling);
  p.add("quats", t.rotations, config.lr_rotation);
  p.add("features", t.features, config.lr_feature, true, /*steps_without_gradient=*/true);
  at::Generator gen = seededGenerator(config.seed, RandomPurpose::kDecoderInit, 0);
  const double bound = 1.0 / std::sqrt(std::max(1, s.config.feature_dim));
  p.add("decoder_w",
        at::empty({s.num_classes, s.config.feature_dim}).uniform_(-bound, bound, gen).to(s.device),
        config.lr_decoder, false);
  p.add("decoder_b", at::zeros({s.num_classes}, at::TensorOptions().device(s.device)),
        config.lr_decoder, false);
  p.add("log_alpha", at::full({p.rows()}, config.log_alpha_init, t.means.options()),
        config.lr_log_alpha);
  const auto fopts = at::TensorOptions().dtype(at::kFloat).device(s.device);
  s.densification = makeDefaultDensification(s.config, s.config, s.extent);
  s.densification->initialise(p.rows(), fopts);
  s.drop.initialise(p.rows(), fopts);
}

void Trainer::setDropStrategy(std::shared_ptr<const DropStrategy> strategy) {
  state_->drop.setStrategy(std::move(strategy));
}

void Trainer::setProfile(StepProfile::Ptr profile) { state_->profile = std::move(profile); }

void Trainer::setCollective(Collective::Ptr collective) {
  state_->collective = std::move(collective);
}

Trainer::~Trainer() = default;

int Trainer::iteration() const { return state_->iteration; }
const TrainConfig& Trainer::config() const { return state_->config; }
std::int64_t Trainer::numGaussians() const { return state_->params.rows(); }
GaussianParams Trainer::parameters() const { return state_->params.gaussians(); }

StepStats Trainer::step(bool read_losses) {
  State& s = *state_;
  if (s.views.cameras_only) {
    throw Error("<trainer>", "views", "a trainer made with its training views (kLoaded)",
                "cameras only (made for rendering)");
  }
  const TrainConfig& c = s.config;
  const int it = s.iteration;
  StepProfile* profile = s.profile.get();
  const ActiveProfileScope active(profile);  // the rasterizer's steps show as nested phases
  enterPhase(profile, "views and parameters");
  // Position learning rate: exponential from init to final over the run (3DGS).
  const double t = std::min(1.0, static_cast<double>(it) / std::max(1, c.iterations));
  s.params["means"].lr =
      std::exp(std::log(c.lr_position_init) * (1 - t) + std::log(c.lr_position_final) * t) *
      s.extent;

  // This iteration's views (this rank's share of the global batch) and which of the features'
  // and the decoder's gradients any rank of the group has this step.
  StepPass pass;
  pass.ranks = s.collective ? s.collective->size() : 1;
  pass.batch = c.views_per_step * pass.ranks;
  pass.read_losses = read_losses;
  const int rank = s.collective ? s.collective->rank() : 0;
  s.views.prefetch(c, it, rank, pass.ranks);  // views read from a scene cache: the coming steps'
  const StepViews step_views =
      drawStepViews(s.views, c, it, rank, pass.ranks, s.collective != nullptr);
  pass.views = step_views.views;
  pass.settings.sh_degree = s.shDegree();
  pass.settings.background = c.background;
  pass.g = s.params.gaussians();
  const bool gated = s.drop.gated(it);
  pass.settings.closed_gate_gradients = gated && c.closed_gate_gradients;
  if (s.drop.refreshesL0Weights(it)) {
    enterPhase(profile, "L0 weights");
    s.drop.refreshL0Weights(s.params, s.views, s.iteration);
  }
  s.renderLossesBackward(pass, it, s.tile_capacity.get());
  StepStats stats;
  if (s.tile_capacity) {
    enterPhase(profile, "tile list check");  // where the host may wait for the GPU
    if (!s.tile_capacity->renderedAll()) {
      // A render's (Gaussian, tile) list, sized from earlier renders, was too short: its image
      // and gradients miss pairs. Again with lists sized by the exact counts (rare: a jump in
      // the count past the capacity's margin).
      for (Parameter& p : s.params.all()) p.value.mutable_grad() = at::Tensor();
      s.renderLossesBackward(pass, it, nullptr);
      stats.rendered_again = true;
    }
  }
  {
    c10::AutoGradMode no_grad(false);
    s.reduceAndUpdate(pass, step_views, it);
    s.iteration = it + 1;
    s.afterUpdate(s.iteration, gated, stats);
  }
  stats.iteration = s.iteration;
  stats.losses_read = read_losses;
  if (read_losses) {
    s.readLossValues(pass, stats);
  } else {
    stats.loss = stats.rgb_loss = stats.semantic_loss = std::numeric_limits<double>::quiet_NaN();
  }
  if (profile) {
    profile->leave();
    profile->countIteration();
  }
  stats.num_gaussians = s.params.rows();
  stats.drop_pressure = s.drop.pressure();
  stats.recovery_started = s.iteration == s.drop.recoveryStart();
  stats.pseudo_labelled_views = s.views.pseudo_labelled_views;
  return stats;
}

RenderResult Trainer::renderView(const io::View& view) const {
  return renderCamera(RasterCamera::fromPinhole(view.camera));
}

RenderResult Trainer::renderCamera(const RasterCamera& camera) const {
  return renderCamera(camera, at::Tensor());
}

RenderResult Trainer::renderCamera(const RasterCamera& camera, const at::Tensor& keep) const {
  c10::AutoGradMode no_grad(false);
  const State& s = *state_;
  return render(s.evaluationGaussians(keep), camera, s.evaluationSettings());
}

RenderResult Trainer::renderCameraWith(const RasterCamera& camera, const at::Tensor& features,
                                       const at::Tensor& keep) const {
  c10::AutoGradMode no_grad(false);
  const State& s = *state_;
  GaussianParams g = s.evaluationGaussians(keep);
  if (!features.defined() || features.dim() != 2 || features.size(0) != g.means.size(0)) {
    throw Error("<render>", "features",
                "one row per Gaussian (" + std::to_string(g.means.size(0)) + ")",
                features.defined() ? std::to_string(features.size(0)) + " rows" : "none");
  }
  g.features = features.to(g.means.device(), g.means.scalar_type()).contiguous();
  return render(g, camera, s.evaluationSettings());
}

RenderResult Trainer::renderDepth(const RasterCamera& camera, const at::Tensor& keep) const {
  c10::AutoGradMode no_grad(false);
  const State& s = *state_;
  RenderSettings settings = s.evaluationSettings();
  settings.features = false;
  return render(s.evaluationGaussians(keep), camera, settings);
}

at::Tensor Trainer::predictClasses(const RenderResult& r) const {
  c10::AutoGradMode no_grad(false);
  const at::Tensor logits = state_->decode(r.features);
  // argmax of cos(decoded, one-hot class embedding) = argmax of the decoded vector.
  return logits.argmax(2);
}

at::Tensor Trainer::classCosines(const RenderResult& r) const { return classCosines(r.features); }

at::Tensor Trainer::classCosines(const at::Tensor& features) const {
  c10::AutoGradMode no_grad(false);
  if (numClasses() == 0) return at::Tensor();
  const at::Tensor& w = state_->params["decoder_w"].value;
  const at::Tensor d = state_->decode(features.to(w.device(), w.scalar_type()));
  return d / d.norm(2, 2, true).clamp_min(1e-12);
}

SurfaceLayer Trainer::renderSurface(const RasterCamera& camera, double level, bool features,
                                    const at::Tensor& keep) const {
  c10::AutoGradMode no_grad(false);
  GaussianParams g = state_->evaluationGaussians(keep);
  if (!features) g.features = at::Tensor();
  return renderSurfaceLayer(g, camera, level);
}

at::Tensor Trainer::renderedClassWeights(const std::vector<RasterCamera>& cameras) const {
  if (numClasses() == 0) {
    throw Error("<trainer>", "classes", "a semantic model to weigh classes", "none");
  }
  const auto class_map = [&](std::size_t k) { return predictClasses(renderCamera(cameras[k])); };
  c10::AutoGradMode no_grad(false);
  return classWeightSums(state_->evaluationGaussians(), cameras, class_map, numClasses())
      .to(at::kCPU);
}

at::Tensor Trainer::renderedDepthResiduals(const std::vector<RasterCamera>& cameras,
                                           SurfaceDepth against) const {
  c10::AutoGradMode no_grad(false);
  const GaussianParams g = state_->evaluationGaussians();
  if (against == SurfaceDepth::kExpected) {
    const auto depth_map = [&](std::size_t k) { return renderDepth(cameras[k]).depth; };
    return depthResiduals(g, cameras, depth_map).to(at::kCPU);
  }
  return gapsFromCameraSums(g.means.size(0), at::kCPU, cameras.size(),
                            [&](std::size_t k) { return surfaceGapSums(g, cameras[k], 0.5); });
}

int Trainer::numClasses() const { return static_cast<int>(state_->num_classes); }

pcl::PointCloud<GaussianPoint> Trainer::toCloud() const {
  c10::AutoGradMode no_grad(false);
  const State& s = *state_;
  const ParameterStore& p = s.params;
  GaussianTensors t;
  t.means = p["means"].value.detach();
  t.normals = at::zeros_like(t.means);
  t.sh_dc = p["sh_dc"].value.detach();
  t.sh_rest = p["sh_rest"].value.detach();
  t.opacity_logit = p["opacity"].value.detach();
  t.log_scales = p["scales"].value.detach();
  t.rotations = p["quats"].value.detach();
  t.features = p["features"].value.detach();
  t.log_alpha = p["log_alpha"].value.detach();
  t.confidence = s.drop.confidence();
  t.labels = t.features.size(1) > 0 ? s.decode(t.features).argmax(1)
                                    : at::full({p.rows()}, -1, t.means.options().dtype(at::kLong));
  return gaussians::toCloud(t);
}

at::Tensor Trainer::effectiveOpacity() const {
  return state_->drop.effectiveOpacity(state_->params, state_->iteration).to(at::kCPU);
}

void Trainer::setGaussians(const pcl::PointCloud<GaussianPoint>& cloud) {
  if (cloud.empty()) throw Error("<setGaussians>", "Gaussians", "at least one", "none");
  TensorArchive a = checkpointSnapshot();
  const std::int64_t d = state_->params["features"].value.size(1);
  const GaussianTensors t = fromCloud(cloud, at::kCPU, static_cast<int>(d));
  const std::map<std::string, at::Tensor> values = {
      {"means", t.means},           {"sh_dc", t.sh_dc},        {"sh_rest", t.sh_rest},
      {"opacity", t.opacity_logit}, {"scales", t.log_scales},  {"quats", t.rotations},
      {"features", t.features},     {"log_alpha", t.log_alpha}};
  for (const std::string& name : checkpointRowTensors()) {
    auto entry = a.tensors.find(name);
    if (entry == a.tensors.end() || !entry->second.defined()) continue;
    at::Tensor& old = entry->second;
    const auto value = values.find(name);
    if (value != values.end()) {
      if (value->second.sizes().slice(1) != old.sizes().slice(1)) {
        throw Error("<setGaussians>", name, "rows shaped as the model's", "another shape");
      }
      old = value->second.to(old.scalar_type()).contiguous();
    } else {
      std::vector<std::int64_t> shape = old.sizes().vec();
      shape[0] = t.size();
      old = at::zeros(shape, old.options());
    }
  }
  loadCheckpoint(a, "<setGaussians>");
}

TensorArchive Trainer::checkpointSnapshot() const {
  const State& s = *state_;
  TensorArchive a;
  s.params.save(a);
  s.drop.save(a);
  s.densification->save(a);
  a.numbers["iteration"] = s.iteration;
  a.numbers["num_classes"] = s.num_classes;
  // Copies, also of CPU tensors: the optimiser updates the live ones in place.
  for (auto& entry : a.tensors) {
    if (entry.second.defined()) {
      entry.second = entry.second.detach().to(at::kCPU, /*non_blocking=*/false, /*copy=*/true);
    }
  }
  return a;
}

void Trainer::saveCheckpoint(const std::string& path) const {
  writeTensorArchive(path, checkpointSnapshot());
}

void Trainer::loadCheckpoint(const std::string& path) {
  loadCheckpoint(readTensorArchive(path), path);
}

std::vector<std::string> Trainer::checkpointRowTensors() const {
  const State& s = *state_;
  std::vector<std::string> names = s.params.rowTensors();
  for (const auto& list : {s.drop.rowTensors(), s.densification->rowTensors()})
    names.insert(names.end(), list.begin(), list.end());
  return names;
}

void Trainer::loadCheckpoint(const TensorArchive& a, const std::string& path) {
  State& s = *state_;
  if (static_cast<int>(a.number("num_classes", path)) != s.num_classes) {
    throw Error(path, "num_classes", "the scene's class count " + std::to_string(s.num_classes),
                std::to_string(static_cast<int>(a.number("num_classes", path))));
  }
  s.params.load(a, path, s.device);
  s.drop.load(a, path, s.device);
  s.densification->load(a, path, s.device);
  s.iteration = static_cast<int>(a.number("iteration", path));
  checkConsistency();
}

void Trainer::checkConsistency() const {
  const State& s = *state_;
  s.params.checkRows();
  s.drop.checkRows(s.params.rows());
  s.densification->checkRows(s.params.rows());
}

}  // namespace gaussians
}  // namespace sadsplat
