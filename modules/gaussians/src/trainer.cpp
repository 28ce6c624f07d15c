#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/gaussians/view_coverage.h"

#include <ATen/CPUGeneratorImpl.h>
#include <c10/core/GradMode.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>
#include <utility>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/adam.h"
#include "sadsplat/gaussians/contribution.h"
#include "sadsplat/gaussians/counter_random.h"
#include "sadsplat/gaussians/densification_stats.h"
#include "sadsplat/gaussians/gaussian_tensors.h"
#include "sadsplat/gaussians/image_metrics.h"
#include "sadsplat/gaussians/initialization.h"
#include "sadsplat/gaussians/semantic_loss.h"
#include "sadsplat/gaussians/tensor_archive.h"

namespace sadsplat {
namespace gaussians {
namespace trainer_detail {

// One optimised tensor with its Adam moments (per-row tensors are resized by densification).
// Not in the anonymous namespace: Trainer::State holds these, and a type with linkage must not
// hold one without (GCC's -Wsubobject-linkage in unity builds).
struct Param {
  std::string name;
  at::Tensor value, m, v;
  double lr = 0;
  bool per_gaussian = true;
};

}  // namespace trainer_detail
using trainer_detail::Param;

namespace {

double logit(double p) { return std::log(p / (1 - p)); }

// log_alpha of a gate folded into its opacity: sigmoid(20) * 1.2 - 0.1 > 1, so the deterministic
// gate is exactly 1, and so is every training sample (the noise's logit is clamped to +-13.8).
constexpr double kSettledLogAlpha = 20.0;

}  // namespace

at::Generator seededGenerator(std::uint64_t seed, std::uint64_t purpose, std::uint64_t iteration) {
  return at::detail::createCPUGenerator(mixBits(seed ^ mixBits(purpose ^ mixBits(iteration))));
}

struct Trainer::State {
  TrainConfig config;
  at::Device device{at::kCPU};
  int iteration = 0;
  double extent = 1;
  int num_classes = 0;
  // Scene data on the device.
  std::vector<RasterCamera> cameras;
  std::vector<at::Tensor> images;       // [H, W, 3] float in [0, 1]
  std::vector<at::Tensor> masks;        // [H, W] float, 1 = valid pixel
  std::vector<at::Tensor> labels;       // [H, W] int64, -1 = not supervised (empty if unlabelled)
  std::vector<double> semantic_weight;  // per view: lambda_semantic (GT) or lambda_pseudo
  std::vector<at::Tensor> confidence_maps;  // [H, W] max class confidence (empty if none)
  int pseudo_labelled_views = 0;
  std::vector<int> train_views, labelled_views;
  // Parameters: means, sh_dc, sh_rest, opacity, scales, quats, features; decoder W, b.
  std::vector<Param> params;
  at::Tensor confidence;  // [N] last semantic confidence computed by the drop (0 before)
  at::Tensor l0_weights;  // [N] weight of each Gaussian in the L0 term (TrainConfig::l0_importance)
  std::shared_ptr<const DropStrategy> drop;
  StepProfile::Ptr profile;
  Collective::Ptr collective;
  // Densification statistics.
  at::Tensor grad_accum, denom, max_radii;
  std::int64_t adam_step = 0;

  Param& p(const std::string& name) {
    for (auto& q : params) {
      if (q.name == name) return q;
    }
    throw Error("<trainer>", name, "a known parameter");
  }
  const Param& p(const std::string& name) const { return const_cast<State*>(this)->p(name); }
  std::int64_t n() const { return params[0].value.size(0); }

  GaussianParams gaussians() const {
    GaussianParams g;
    g.means = p("means").value;
    g.quats = p("quats").value;
    g.log_scales = p("scales").value;
    g.opacity_logits = p("opacity").value;
    g.sh = at::cat({p("sh_dc").value, p("sh_rest").value}, 1);
    g.features = p("features").value;
    return g;
  }

  int shDegree() const {
    return std::min(config.max_sh_degree, iteration / std::max(1, config.sh_increase_interval));
  }

  at::Tensor decode(const at::Tensor& features) const {
    return at::linear(features, p("decoder_w").value, p("decoder_b").value);
  }

  // Keeps the Gaussians where `keep` is true, then appends `extra` rows (per parameter name).
  void resize(const at::Tensor& keep, const std::map<std::string, at::Tensor>& extra) {
    const at::Tensor idx = keep.nonzero().squeeze(1);
    for (Param& q : params) {
      if (!q.per_gaussian) continue;
      at::Tensor value = q.value.detach().index_select(0, idx);
      at::Tensor m = q.m.index_select(0, idx), v = q.v.index_select(0, idx);
      const auto it = extra.find(q.name);
      if (it != extra.end()) {
        value = at::cat({value, it->second.detach()}, 0);
        m = at::cat({m, at::zeros_like(it->second)}, 0);
        v = at::cat({v, at::zeros_like(it->second)}, 0);
      }
      q.value = value.contiguous().requires_grad_(true);
      q.m = m.contiguous();
      q.v = v.contiguous();
    }
    const std::int64_t added = extra.empty() ? 0 : extra.begin()->second.size(0);
    auto grow = [&](const at::Tensor& t, const at::Tensor& fill) {
      at::Tensor kept = t.index_select(0, idx);
      return added > 0 ? at::cat({kept, fill}, 0) : kept;
    };
    confidence = grow(confidence, at::zeros({added}, confidence.options()));
    l0_weights = grow(l0_weights, at::ones({added}, l0_weights.options()));
    grad_accum = grow(grad_accum, at::zeros({added}, grad_accum.options()));
    denom = grow(denom, at::zeros({added}, denom.options()));
    max_radii = grow(max_radii, at::zeros({added}, max_radii.options()));
  }

  // The first iteration of the recovery phase (TrainConfig::recovery_iterations): from there on
  // no gates, no L0 term and no drops. Past the end without a drop or a recovery.
  int recoveryStart() const {
    return config.recovery_iterations > 0 ? config.iterations - config.recovery_iterations
                                          : config.iterations + 1;
  }
  // Whether iteration `it` (0-based) trains with the drop's gates.
  bool gated(int it) const { return drop && it < recoveryStart(); }

  // The drop's deterministic (evaluation) gate per Gaussian; undefined without one, and once the
  // gates are folded into the opacities.
  at::Tensor evaluationGate() const {
    return gated(iteration) ? drop->evaluationGate(p("log_alpha").value.detach()) : at::Tensor();
  }

  // Start of the recovery phase: with a drop, the Gaussians with a closed gate go and the other
  // gates are folded into the opacities (their log_alpha fixed open); then, with recovery_prune,
  // the share of Gaussians that contribute least to the training views goes. Returns
  // {closed, pruned}.
  std::pair<std::int64_t, std::int64_t> settleGates() {
    std::int64_t closed = 0, pruned = 0;
    const at::Tensor gate =
        drop ? drop->evaluationGate(p("log_alpha").value.detach()) : at::Tensor();
    if (gate.defined()) {
      const at::Tensor open = gate > 0;
      closed = n() - open.sum().item<std::int64_t>();
      resize(open, {});
      const at::Tensor kept_gate = gate.index_select(0, open.nonzero().squeeze(1));
      Param& o = p("opacity");
      const at::Tensor folded = (at::sigmoid(o.value.detach()) * kept_gate).clamp(1e-6, 1 - 1e-6);
      o.value = at::logit(folded).contiguous().requires_grad_(true);
      Param& la = p("log_alpha");
      la.value = at::full_like(la.value.detach(), kSettledLogAlpha).requires_grad_(true);
      la.m.zero_();
      la.v.zero_();
    }
    if (config.recovery_prune > 0 && n() > 0) {
      const at::Tensor score = blendingWeightSums(gaussians(), trainingCameras());
      const std::int64_t count =
          static_cast<std::int64_t>(std::floor(config.recovery_prune * static_cast<double>(n())));
      if (count > 0) {
        // The `count` lowest scores go (ties by index: a stable sort keeps this deterministic).
        const at::Tensor order = std::get<1>(score.sort(/*stable=*/true, 0, false));
        at::Tensor keep = at::ones({n()}, score.options().dtype(at::kBool));
        keep.index_fill_(0, order.narrow(0, 0, count), false);
        pruned = count;
        resize(keep, {});
      }
    }
    return {closed, pruned};
  }

  std::vector<RasterCamera> trainingCameras() const {
    std::vector<RasterCamera> training;
    for (int v : train_views) training.push_back(cameras[v]);
    return training;
  }

  // Whether the L0 term's weights are recomputed before iteration `it`: with l0_importance, when
  // the L0 schedule starts and every drop interval after (a fixed schedule, so that a resumed run
  // recomputes them where an uninterrupted one does; between, they follow the Gaussians' rows).
  bool refreshesL0Weights(int it) const {
    return gated(it) && config.l0_importance > 0 && config.drop_interval > 0 &&
           it >= config.lambda_l0_from && (it - config.lambda_l0_from) % config.drop_interval == 0;
  }
  // The L0 weights from each Gaussian's contribution to the training views as rendered for
  // evaluation (opacity x deterministic gate).
  void refreshL0Weights() {
    GaussianParams g = gaussians();
    g.opacity_gate = evaluationGate();
    l0_weights =
        inverseContributionWeights(blendingWeightSums(g, trainingCameras()), config.l0_importance);
  }

  // Activated opacity times the evaluation gate (when there is one).
  at::Tensor effectiveOpacity() const {
    const at::Tensor opacity = at::sigmoid(p("opacity").value.detach());
    const at::Tensor gate = evaluationGate();
    return gate.defined() ? opacity * gate : opacity;
  }

  // What view v trains besides the picture: the features (it has a semantic loss) and the
  // decoder (the loss also trains it).
  struct ViewRole {
    bool semantic = false;
    bool decoder_learns = false;
  };
  ViewRole role(int v) const {
    ViewRole r;
    r.semantic = labels[v].defined() && semantic_weight[v] > 0 && config.feature_dim > 0;
    // Ground truth always trains the decoder; pseudo-labels when the configuration says so.
    const bool ground_truth =
        std::find(labelled_views.begin(), labelled_views.end(), v) != labelled_views.end();
    r.decoder_learns = r.semantic && (ground_truth || config.pseudo_labels_train_decoder);
    return r;
  }

  // Sums every parameter's gradient and the step's densification sums (`sums`, per Gaussian)
  // over the ranks in one flat all-reduce, without a host synchronisation. Which gradients exist
  // somewhere in the group is known on every rank from the global batch's views
  // (`features_anywhere`, `decoder_anywhere`; the other parameters have a gradient on every rank
  // or on none): one that no rank has stays undefined and is not sent (Adam skips that tensor as
  // a single process would); one that only some ranks have counts as zero on the others.
  void reduceGradients(bool features_anywhere, bool decoder_anywhere,
                       const std::vector<at::Tensor*>& sums) {
    std::vector<at::Tensor> parts;
    std::vector<Param*> sent;
    for (Param& q : params) {
      const at::Tensor grad = q.value.grad();
      bool anywhere = grad.defined();
      if (q.name == "features") anywhere = features_anywhere;
      if (q.name == "decoder_w" || q.name == "decoder_b") anywhere = decoder_anywhere;
      if (grad.defined() && !anywhere) {
        throw std::logic_error("trainer: gradient of " + q.name + " outside the global batch");
      }
      if (!anywhere) continue;
      parts.push_back(grad.defined() ? grad.reshape({-1})
                                     : at::zeros({q.value.numel()}, q.value.options()));
      sent.push_back(&q);
    }
    for (at::Tensor* sum : sums) parts.push_back(sum->reshape({-1}));
    at::Tensor flat = at::cat(parts);
    collective->sum(flat);
    int64_t offset = 0;
    for (Param* q : sent) {
      const int64_t n = q->value.numel();
      q->value.mutable_grad() = flat.slice(0, offset, offset + n).view(q->value.sizes());
      offset += n;
    }
    for (at::Tensor* sum : sums) {
      const int64_t n = sum->numel();
      *sum = flat.slice(0, offset, offset + n).view(sum->sizes());
      offset += n;
    }
  }

  void densifyAndPrune(bool prune_big) {
    const double threshold = config.densify_grad_threshold;
    const at::Tensor avg = grad_accum / denom.clamp_min(1);
    const at::Tensor scales = p("scales").value.detach().exp();
    const at::Tensor max_scale = std::get<0>(scales.max(1));
    const at::Tensor big_grad = avg >= threshold;
    const double dense = config.percent_dense * extent;
    const bool room = n() < config.max_gaussians;
    const at::Tensor clone = room ? big_grad & (max_scale <= dense) : at::zeros_like(big_grad);
    const at::Tensor split = room ? big_grad & (max_scale > dense) : at::zeros_like(big_grad);

    std::map<std::string, at::Tensor> extra;
    const at::Tensor clone_idx = clone.nonzero().squeeze(1);
    const at::Tensor split_idx = split.nonzero().squeeze(1);
    // Split: two samples from each large Gaussian, scales divided by 1.6 (3DGS).
    at::Tensor split_means;
    {
      const at::Tensor s = scales.index_select(0, split_idx).repeat({2, 1});
      at::Generator gen = seededGenerator(config.seed, 7, static_cast<std::uint64_t>(iteration));
      const at::Tensor noise = at::normal(0.0, 1.0, {s.size(0), 3}, gen).to(device) * s;
      const at::Tensor q = p("quats").value.detach().index_select(0, split_idx).repeat({2, 1});
      const at::Tensor qn = q / q.norm(2, 1, true);
      const at::Tensor w = qn.select(1, 0), x = qn.select(1, 1), y = qn.select(1, 2),
                       z = qn.select(1, 3);
      const at::Tensor R =
          at::stack({1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                     2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                     2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
                    1)
              .view({-1, 3, 3});
      split_means = at::bmm(R, noise.unsqueeze(2)).squeeze(2) +
                    p("means").value.detach().index_select(0, split_idx).repeat({2, 1});
    }
    for (const Param& q : params) {
      if (!q.per_gaussian) continue;
      const at::Tensor src = q.value.detach();
      const at::Tensor cloned = src.index_select(0, clone_idx);
      std::vector<int64_t> reps(static_cast<std::size_t>(src.dim()), 1);
      reps[0] = 2;
      at::Tensor splitted = src.index_select(0, split_idx).repeat(reps);
      if (q.name == "means") splitted = split_means;
      if (q.name == "scales") splitted = splitted - std::log(1.6);
      extra[q.name] = at::cat({cloned, splitted}, 0);
    }
    // Originals of split Gaussians go; so do transparent (and, later, huge) ones. Transparent
    // means the opacity a Gaussian renders with at evaluation: times its deterministic gate.
    at::Tensor keep = split.logical_not();
    const at::Tensor opacity = effectiveOpacity();
    at::Tensor remove = opacity < config.min_opacity;
    if (prune_big) {
      remove = remove | (max_radii > config.max_screen_radius) | (max_scale > 0.1 * extent);
    }
    keep = keep & remove.logical_not();
    resize(keep, extra);
    grad_accum.zero_();
    denom.zero_();
    max_radii.zero_();
  }
};

Trainer::Trainer(const io::Scene& scene, const TrainConfig& config) : state_(new State) {
  State& s = *state_;
  s.config = config;
  if (config.iterations < 1 || config.feature_dim < 0 || config.feature_dim > kFeatureDim ||
      config.max_sh_degree < 0 || config.max_sh_degree > 3 || config.semantic_interval < 0 ||
      config.views_per_step < 1) {
    throw Error("<config>",
                "iterations / feature_dim / max_sh_degree / semantic_interval / views_per_step",
                "iterations >= 1, feature_dim 0..32, max_sh_degree 0..3, semantic_interval >= 0, "
                "views_per_step >= 1");
  }
  if (config.recovery_iterations < 0 || config.recovery_iterations >= config.iterations) {
    throw Error("<config>", "recovery_iterations", "0 .. iterations - 1",
                std::to_string(config.recovery_iterations));
  }
  if (!(config.l0_importance >= 0)) {
    throw Error("<config>", "l0_importance", "a non-negative exponent",
                std::to_string(config.l0_importance));
  }
  if (!(config.recovery_prune >= 0 && config.recovery_prune < 1)) {
    throw Error("<config>", "recovery_prune", "a share in [0, 1)",
                std::to_string(config.recovery_prune));
  }
  if (config.device == "cuda") {
    if (!at::hasCUDA()) {
      throw Error("<config>", "device", "cpu (no CUDA device or no CUDA build here)", "cuda");
    }
    s.device = at::Device(at::kCUDA, 0);
  } else if (config.device != "cpu") {
    throw Error("<config>", "device", "cpu or cuda", config.device);
  }
  if (s.config.densify_until < 0) s.config.densify_until = config.iterations / 2;
  s.num_classes = static_cast<int>(scene.classes.size());
  if (s.num_classes < 1) throw Error(scene.source, "classes", "at least one class");

  // Views: images, masks, labels on the device; cameras; scene extent from the camera centres.
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const io::View& v = scene.views[i];
    s.cameras.push_back(RasterCamera::fromPinhole(v.camera));
    if (!v.train) {
      s.images.emplace_back();
      s.masks.emplace_back();
      s.labels.emplace_back();
      s.semantic_weight.push_back(0.0);
      s.confidence_maps.emplace_back();
      continue;
    }
    const int H = v.camera.height, W = v.camera.width;
    at::Tensor rgb = at::from_blob(const_cast<std::uint8_t*>(v.rgb.pixels.data()), {H, W, 3},
                                   at::TensorOptions().dtype(at::kByte))
                         .to(at::kFloat)
                         .div(255.0);
    at::Tensor mask = at::from_blob(const_cast<std::uint8_t*>(v.mask.pixels.data()), {H, W},
                                    at::TensorOptions().dtype(at::kByte))
                          .to(at::kFloat)
                          .div(255.0);
    s.images.push_back(rgb.to(s.device));
    s.masks.push_back(mask.to(s.device));
    // Semantic supervision (ground truth wins, then kept pseudo-labels) and the confidence map
    // of the drop (1 on ground-truth pixels, else the pseudo-label backend's max class score).
    at::Tensor labels, confidence;
    const bool gt = v.labelled && !v.labels.empty();
    const std::vector<std::int16_t> sup = io::supervisionLabels(v, config.use_pseudo_labels);
    if (std::any_of(sup.begin(), sup.end(), [](std::int16_t l) { return l >= 0; })) {
      labels = at::from_blob(const_cast<std::int16_t*>(sup.data()), {H, W},
                             at::TensorOptions().dtype(at::kShort))
                   .to(at::kLong);
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
    s.labels.push_back(labels.defined() ? labels.to(s.device) : labels);
    s.semantic_weight.push_back(gt ? config.lambda_semantic : config.lambda_pseudo);
    s.confidence_maps.push_back(confidence.defined() ? confidence.to(s.device) : confidence);
    s.train_views.push_back(static_cast<int>(i));
  }
  if (s.train_views.empty()) throw Error(scene.source, "split", "at least one training view");
  s.extent = sceneExtent(s.cameras);

  // Initial Gaussians (3DGS initialisation, features N(0, 0.01)).
  InitOptions init;
  init.seed = config.seed;
  const GaussianTensors t =
      fromCloud(initialCloud(scene.points, init), s.device, config.feature_dim);
  auto add = [&](const std::string& name, const at::Tensor& value, double lr,
                 bool per_gaussian = true) {
    Param q;
    q.name = name;
    q.value = value.detach().clone().contiguous().requires_grad_(true);
    q.m = at::zeros_like(q.value);
    q.v = at::zeros_like(q.value);
    q.lr = lr;
    q.per_gaussian = per_gaussian;
    s.params.push_back(q);
  };
  add("means", t.means, config.lr_position_init * s.extent);
  add("sh_dc", t.sh_dc, config.lr_sh_dc);
  add("sh_rest", t.sh_rest, config.lr_sh_rest);
  add("opacity", t.opacity_logit, config.lr_opacity);
  add("scales", t.log_scales, config.lr_scaling);
  add("quats", t.rotations, config.lr_rotation);
  add("features", t.features, config.lr_feature);
  at::Generator gen = seededGenerator(config.seed, 3, 0);
  const double bound = 1.0 / std::sqrt(std::max(1, config.feature_dim));
  add("decoder_w",
      at::empty({s.num_classes, config.feature_dim}).uniform_(-bound, bound, gen).to(s.device),
      config.lr_decoder, false);
  add("decoder_b", at::zeros({s.num_classes}, at::TensorOptions().device(s.device)),
      config.lr_decoder, false);
  add("log_alpha", at::full({s.n()}, config.log_alpha_init, t.means.options()),
      config.lr_log_alpha);
  const auto fopts = at::TensorOptions().dtype(at::kFloat).device(s.device);
  s.grad_accum = at::zeros({s.n()}, fopts);
  s.denom = at::zeros({s.n()}, fopts);
  s.max_radii = at::zeros({s.n()}, fopts);
  s.confidence = at::zeros({s.n()}, fopts);
  s.l0_weights = at::ones({s.n()}, fopts);
}

void Trainer::setDropStrategy(std::shared_ptr<const DropStrategy> strategy) {
  state_->drop = std::move(strategy);
}

void Trainer::setProfile(StepProfile::Ptr profile) { state_->profile = std::move(profile); }

void Trainer::setCollective(Collective::Ptr collective) {
  state_->collective = std::move(collective);
}

Trainer::~Trainer() = default;

int Trainer::iteration() const { return state_->iteration; }
const TrainConfig& Trainer::config() const { return state_->config; }
std::int64_t Trainer::numGaussians() const { return state_->n(); }
GaussianParams Trainer::parameters() const { return state_->gaussians(); }

StepStats Trainer::step(bool read_losses) {
  State& s = *state_;
  const TrainConfig& c = s.config;
  const int it = s.iteration;
  StepProfile* profile = s.profile.get();
  const ActiveProfileScope active(profile);  // the rasterizer's steps show as nested phases
  enterPhase(profile, "views and parameters");
  // Position learning rate: exponential from init to final over the run (3DGS).
  const double t = std::min(1.0, static_cast<double>(it) / std::max(1, c.iterations));
  s.p("means").lr =
      std::exp(std::log(c.lr_position_init) * (1 - t) + std::log(c.lr_position_final) * t) *
      s.extent;

  // This iteration's views: the next one of a seeded shuffle of the training views, and every
  // semantic_interval iterations the next labelled view.
  auto pick = [&](const std::vector<int>& views, std::uint64_t purpose, int counter) {
    const int n = static_cast<int>(views.size());
    const int epoch = counter / n, pos = counter % n;
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::vector<std::uint64_t> keys(n);
    for (int i = 0; i < n; ++i)
      keys[i] = mixBits(c.seed ^ mixBits(purpose ^ mixBits(epoch * 1000003ull + i)));
    std::sort(order.begin(), order.end(), [&](int a, int b) { return keys[a] < keys[b]; });
    return views[order[pos]];
  };
  // Data-parallel ranks split one global batch of views_per_step x ranks draws: this rank's
  // draws are numbered rank * views_per_step + b, so N ranks draw what one process with N times
  // the views per step would.
  const int ranks = s.collective ? s.collective->size() : 1;
  const int rank = s.collective ? s.collective->rank() : 0;
  const int batch = c.views_per_step * ranks;
  const bool semantic_step = !s.labelled_views.empty() && c.semantic_interval > 0 &&
                             c.lambda_semantic > 0 && it % c.semantic_interval == 0;
  // The views of one draw: a training view, on semantic steps also a labelled one.
  auto drawViews = [&](int draw, std::vector<int>* views) {
    const int tv = pick(s.train_views, 1, it * batch + draw);
    views->push_back(tv);
    if (semantic_step) {
      const int lv = pick(s.labelled_views, 2, (it / c.semantic_interval) * batch + draw);
      if (lv != tv) views->push_back(lv);
    }
  };
  std::vector<int> views;
  for (int b = 0; b < c.views_per_step; ++b) drawViews(rank * c.views_per_step + b, &views);
  // Which of the features' and the decoder's gradients any rank of the group has this step.
  bool features_anywhere = false, decoder_anywhere = false;
  if (s.collective) {
    std::vector<int> all;
    for (int draw = 0; draw < batch; ++draw) drawViews(draw, &all);
    for (int v : all) {
      features_anywhere = features_anywhere || s.role(v).semantic;
      decoder_anywhere = decoder_anywhere || s.role(v).decoder_learns;
    }
  }

  RenderSettings settings;
  settings.sh_degree = s.shDegree();
  settings.background = c.background;
  GaussianParams g = s.gaussians();
  const bool gated = s.gated(it);
  if (s.refreshesL0Weights(it)) {
    enterPhase(profile, "L0 weights");
    s.refreshL0Weights();
  }
  if (gated) g.opacity_gate = s.drop->trainingGate(s.p("log_alpha").value, it);
  at::Tensor total;
  // Loss values stay on the device until the end of the step: one host synchronisation per step.
  at::Tensor rgb_sum, sem_sum;
  auto accumulate = [](at::Tensor& sum, const at::Tensor& value) {
    sum = sum.defined() ? sum + value.detach() : value.detach();
  };
  std::vector<RenderResult> renders;
  std::int64_t dropped = 0, closed_at_end = 0, floaters_at_end = 0;
  std::int64_t settled_closed = 0, settled_pruned = 0;
  DropDecision decision;
  for (int v : views) {
    enterPhase(profile, "render forward");
    const at::Tensor& labels = s.labels[v];
    const State::ViewRole role = s.role(v);
    const bool semantic = role.semantic;
    // Training uses no depth, and features only where a semantic loss reads them.
    settings.features = semantic;
    settings.depth = false;
    RenderResult r = render(g, s.cameras[v], settings);
    r.means2d.retain_grad();
    enterPhase(profile, "losses forward");
    const at::Tensor& gt = s.images[v];
    const at::Tensor mask = s.masks[v].unsqueeze(2);
    const at::Tensor l1 = ((r.rgb - gt).abs() * mask).mean();
    const at::Tensor rgb_loss =
        (1 - c.lambda_ssim) * l1 +
        c.lambda_ssim * (1 - (c.fused_ssim ? ssim(r.rgb * mask, gt * mask)
                                           : ssimReference(r.rgb * mask, gt * mask)));
    at::Tensor loss = c.lambda_rgb * rgb_loss;
    accumulate(rgb_sum, rgb_loss);
    if (semantic) {
      // Paper, "Training Loss": 1 - cosine similarity to the class embedding (one-hot in the
      // class-score space of the built-in backend), averaged over supervised pixels only.
      const bool decoder_learns = role.decoder_learns;
      const at::Tensor& w = s.p("decoder_w").value;
      const at::Tensor& b = s.p("decoder_b").value;
      const auto loss_of = c.fused_semantic_loss ? semanticLoss : semanticLossReference;
      const at::Tensor sem = decoder_learns ? loss_of(r.features, labels, w, b)
                                            : loss_of(r.features, labels, w.detach(), b.detach());
      loss = loss + s.semantic_weight[v] * sem;
      accumulate(sem_sum, sem);
    }
    total = total.defined() ? total + loss : loss;
    renders.push_back(r);
  }
  // The mean over the global batch (one draw: the sum of its training and labelled views' losses).
  if (batch > 1) total = total / batch;
  if (gated) {
    // Added once over all ranks.
    const at::Tensor reg = s.drop->regularisation(
        s.p("log_alpha").value, it, c.l0_importance > 0 ? s.l0_weights : at::Tensor());
    if (reg.defined()) total = total + (ranks > 1 ? reg / ranks : reg);
  }
  enterPhase(profile, "backward");
  total.backward();

  {
    c10::AutoGradMode no_grad(false);
    enterPhase(profile, "densification statistics");
    // Densification statistics: NDC-space screen gradient of visible Gaussians (3DGS).
    // Per view, so a batch's mean loss is scaled back by the batch size (3DGS's per-view gradient).
    at::Tensor grad_accum = s.collective ? at::zeros_like(s.grad_accum) : s.grad_accum;
    at::Tensor denom = s.collective ? at::zeros_like(s.denom) : s.denom;
    at::Tensor max_radii = s.max_radii;
    for (std::size_t k = 0; k < renders.size(); ++k) {
      const RenderResult& r = renders[k];
      const RasterCamera& cam = s.cameras[views[k]];
      if (!r.means2d.grad().defined()) continue;
      accumulateScreenGradients(r.means2d.grad(), r.radii, cam.width * 0.5 * batch,
                                cam.height * 0.5 * batch, grad_accum, denom, max_radii);
    }
    if (s.collective) {
      enterPhase(profile, "all-reduce");
      // This step's sums travel with the gradients; the maxima need their own reduction.
      s.reduceGradients(features_anywhere, decoder_anywhere, {&grad_accum, &denom});
      s.collective->max(max_radii);
      s.grad_accum += grad_accum;
      s.denom += denom;
    }
    s.max_radii = max_radii;
    enterPhase(profile, "optimiser");
    // Adam (own, fused implementation so densification can reshape its state). The features
    // take a step with a zero gradient when no view of this iteration rendered them: their
    // momentum carries on, as when they were rendered (and got zero gradient) on every view.
    ++s.adam_step;
    for (Param& q : s.params) {
      const at::Tensor grad = q.value.grad();
      if (!grad.defined() && q.name != "features") continue;
      adamStep(q.value, grad, q.m, q.v, q.lr, s.adam_step);
      if (grad.defined()) q.value.mutable_grad().reset();
    }
    s.iteration = it + 1;
    const int done = s.iteration;
    enterPhase(profile, "drop");
    if (gated && s.drop->dropNow(done)) {
      DropInputs in;
      in.means = s.p("means").value.detach();
      in.opacities = at::sigmoid(s.p("opacity").value.detach());
      in.log_alpha = s.p("log_alpha").value.detach();
      for (int v : s.train_views) {
        if (!s.confidence_maps[v].defined()) continue;
        in.cameras.push_back(s.cameras[v]);
        in.confidence_maps.push_back(s.confidence_maps[v]);
      }
      decision = s.drop->decide(in, done);
      s.confidence = decision.confidence.to(s.device).to(at::kFloat);
      dropped = s.n() - decision.keep.sum().item<std::int64_t>();
      s.resize(decision.keep.to(s.device), {});
    }
    if (done == s.recoveryStart()) {
      std::tie(settled_closed, settled_pruned) = s.settleGates();
    }
    if (done == c.iterations) {
      // Gaussians whose evaluation gate is closed (z = 0) render nothing: removing them at the
      // end changes no render and shrinks the model.
      const at::Tensor gate = s.evaluationGate();
      if (gate.defined()) {
        const at::Tensor open = gate > 0;
        closed_at_end = s.n() - open.sum().item<std::int64_t>();
        if (closed_at_end > 0) s.resize(open, {});
      }
      if (c.prune_floaters) {
        // Floaters: seen by too few training views, or far larger than the scene's detail.
        const at::Tensor keep =
            floaterMask(s.p("means").value, s.p("scales").value, s.trainingCameras(),
                        c.floater_min_views, c.floater_max_scale * s.extent)
                .logical_not();
        floaters_at_end = s.n() - keep.sum().item<std::int64_t>();
        if (floaters_at_end > 0) s.resize(keep, {});
      }
    }
    enterPhase(profile, "densify, prune, reset");
    if (done <= c.densify_until) {
      if (done > c.densify_from && done % c.densify_interval == 0) {
        s.densifyAndPrune(done > c.opacity_reset_interval);
      }
      if (c.opacity_reset_interval > 0 && done % c.opacity_reset_interval == 0) {
        Param& o = s.p("opacity");
        o.value.clamp_max_(logit(0.01));
        o.m.zero_();
        o.v.zero_();
      }
    }
  }
  StepStats stats;
  stats.iteration = s.iteration;
  stats.losses_read = read_losses;
  if (read_losses) {
    enterPhase(profile, "loss values to host");
    const at::Tensor zero = at::zeros({}, total.options());
    at::Tensor values =
        at::stack({total.detach(), rgb_sum, sem_sum.defined() ? sem_sum : zero,
                   at::full({}, static_cast<double>(views.size()), total.options())});
    if (s.collective) s.collective->sum(values);
    values = values.to(at::kDouble).cpu();
    const double* value = values.data_ptr<double>();
    stats.rgb_loss = value[1] / value[3];
    stats.semantic_loss = value[2] / batch;
    stats.loss = value[0];
  } else {
    stats.loss = stats.rgb_loss = stats.semantic_loss = std::numeric_limits<double>::quiet_NaN();
  }
  if (profile) {
    profile->leave();
    profile->countIteration();
  }
  stats.num_gaussians = s.n();
  stats.dropped = dropped;
  stats.removed_closed_gates = closed_at_end;
  stats.removed_floaters = floaters_at_end;
  stats.recovery_started = s.iteration == s.recoveryStart();
  stats.recovery_closed_gates = settled_closed;
  stats.recovery_pruned = settled_pruned;
  stats.drop = decision;
  stats.pseudo_labelled_views = s.pseudo_labelled_views;
  return stats;
}

RenderResult Trainer::renderView(const io::View& view) const {
  c10::AutoGradMode no_grad(false);
  RenderSettings settings;
  settings.sh_degree = state_->shDegree();
  settings.background = state_->config.background;
  GaussianParams g = state_->gaussians();
  g.opacity_gate = state_->evaluationGate();
  return render(g, RasterCamera::fromPinhole(view.camera), settings);
}

at::Tensor Trainer::predictClasses(const RenderResult& r) const {
  c10::AutoGradMode no_grad(false);
  const at::Tensor logits = state_->decode(r.features);
  // argmax of cos(decoded, one-hot class embedding) = argmax of the decoded vector.
  return logits.argmax(2);
}

pcl::PointCloud<GaussianPoint> Trainer::toCloud() const {
  c10::AutoGradMode no_grad(false);
  const State& s = *state_;
  GaussianTensors t;
  t.means = s.p("means").value.detach();
  t.normals = at::zeros_like(t.means);
  t.sh_dc = s.p("sh_dc").value.detach();
  t.sh_rest = s.p("sh_rest").value.detach();
  t.opacity_logit = s.p("opacity").value.detach();
  t.log_scales = s.p("scales").value.detach();
  t.rotations = s.p("quats").value.detach();
  t.features = s.p("features").value.detach();
  t.log_alpha = s.p("log_alpha").value.detach();
  t.confidence = s.confidence;
  t.labels = t.features.size(1) > 0 ? s.decode(t.features).argmax(1)
                                    : at::full({s.n()}, -1, t.means.options().dtype(at::kLong));
  return gaussians::toCloud(t);
}

void Trainer::saveCheckpoint(const std::string& path) const {
  const State& s = *state_;
  TensorArchive a;
  for (const Param& q : s.params) {
    a.tensors[q.name] = q.value.detach();
    a.tensors[q.name + ".m"] = q.m;
    a.tensors[q.name + ".v"] = q.v;
  }
  a.tensors["confidence"] = s.confidence;
  a.tensors["l0_weights"] = s.l0_weights;
  a.tensors["grad_accum"] = s.grad_accum;
  a.tensors["denom"] = s.denom;
  a.tensors["max_radii"] = s.max_radii;
  a.numbers["iteration"] = s.iteration;
  a.numbers["adam_step"] = static_cast<double>(s.adam_step);
  a.numbers["num_classes"] = s.num_classes;
  writeTensorArchive(path, a);
}

void Trainer::loadCheckpoint(const std::string& path) {
  State& s = *state_;
  const TensorArchive a = readTensorArchive(path);
  if (static_cast<int>(a.number("num_classes", path)) != s.num_classes) {
    throw Error(path, "num_classes", "the scene's class count " + std::to_string(s.num_classes));
  }
  for (Param& q : s.params) {
    const at::Tensor& value = a.tensor(q.name, path);
    if (!q.per_gaussian && !value.sizes().equals(q.value.sizes())) {
      throw Error(path, "tensor " + q.name, "the shape of this configuration's " + q.name);
    }
    q.value = value.to(s.device).contiguous().requires_grad_(true);
    q.m = a.tensor(q.name + ".m", path).to(s.device).contiguous();
    q.v = a.tensor(q.name + ".v", path).to(s.device).contiguous();
  }
  s.confidence = a.tensor("confidence", path).to(s.device);
  // Checkpoints written before the importance-weighted L0 have no weights: the plain mean's.
  s.l0_weights = a.tensors.count("l0_weights") ? a.tensor("l0_weights", path).to(s.device)
                                               : at::ones_like(s.confidence);
  s.grad_accum = a.tensor("grad_accum", path).to(s.device);
  s.denom = a.tensor("denom", path).to(s.device);
  s.max_radii = a.tensor("max_radii", path).to(s.device);
  s.iteration = static_cast<int>(a.number("iteration", path));
  s.adam_step = static_cast<std::int64_t>(a.number("adam_step", path));
  checkConsistency();
}

void Trainer::checkConsistency() const {
  const State& s = *state_;
  const std::int64_t n = s.n();
  auto expect = [&](const at::Tensor& t, const std::string& name) {
    if (!t.defined() || t.size(0) != n) {
      throw Error("<trainer>", name, std::to_string(n) + " rows",
                  t.defined() ? std::to_string(t.size(0)) : "undefined");
    }
  };
  for (const Param& q : s.params) {
    if (!q.per_gaussian) continue;
    expect(q.value, q.name);
    expect(q.m, q.name + " Adam m");
    expect(q.v, q.name + " Adam v");
  }
  expect(s.confidence, "confidence");
  expect(s.l0_weights, "l0_weights");
  expect(s.grad_accum, "grad_accum");
  expect(s.denom, "denom");
  expect(s.max_radii, "max_radii");
}

}  // namespace gaussians
}  // namespace sadsplat
