#include "sadsplat/gaussians/densification.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <tuple>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/counter_random.h"
#include "sadsplat/gaussians/densification_stats.h"
#include "sadsplat/gaussians/parameter_store.h"
#include "sadsplat/gaussians/train_config.h"

namespace sadsplat {
namespace gaussians {
namespace {

double logit(double p) { return std::log(p / (1 - p)); }

class DefaultDensification : public DensificationStrategy {
 public:
  DefaultDensification(const DensificationOptions& options, const ScheduleOptions& schedule,
                       double extent)
      : config_{options, schedule}, extent_(extent) {}

  void initialise(std::int64_t rows, const at::TensorOptions& options) override {
    grad_accum_ = at::zeros({rows}, options);
    denom_ = at::zeros({rows}, options);
    max_radii_ = at::zeros({rows}, options);
  }

  std::vector<at::Tensor*> stepPostBackward(const std::vector<RenderResult>& renders,
                                            const std::vector<RasterCamera>& cameras, int batch,
                                            Collective* collective) override {
    // NDC-space screen gradient of visible Gaussians (3DGS), per view, so a batch's mean loss is
    // scaled back by the batch size (3DGS's per-view gradient).
    step_grad_ = collective ? at::zeros_like(grad_accum_) : grad_accum_;
    step_denom_ = collective ? at::zeros_like(denom_) : denom_;
    for (std::size_t k = 0; k < renders.size(); ++k) {
      const RenderResult& r = renders[k];
      if (!r.means2d.grad().defined()) continue;
      accumulateScreenGradients(r.means2d.grad(), r.radii, cameras[k].width * 0.5 * batch,
                                cameras[k].height * 0.5 * batch, step_grad_, step_denom_,
                                max_radii_);
    }
    if (!collective) return {};
    return {&step_grad_, &step_denom_};  // they travel with the gradients
  }

  void reduced(Collective& collective) override {
    collective.max(max_radii_);  // the maxima need their own reduction
    grad_accum_ += step_grad_;
    denom_ += step_denom_;
  }

  void stepPostUpdate(int done, ParameterStore& params,
                      const std::function<at::Tensor()>& effective_opacity,
                      const Resize& resize) override {
    const Settings& c = config_;
    if (c.scale_limit > 0 && done >= c.scale_limit_from) {
      if (done == c.scale_limit_from) splitAbove(params, c.scale_limit * extent_, done, resize);
      // A projection onto the bound (Adam's moments stay as they are). 1e-6 below it, so that
      // exp() of the float log-scale never rounds above the bound (it did by 6e-8 of it).
      params["scales"].value.clamp_max_(std::log(c.scale_limit * extent_) - 1e-6);
    }
    if (done > c.densify_until) {
      // Not 3DGS: after densification, Gaussians that grew beyond large_split_scale x the extent
      // are split (not pruned: they fill surfaces), until the last refinement iterations.
      if (c.large_split_scale > 0 && done % c.densify_interval == 0 &&
          done <= c.iterations - c.large_split_last) {
        splitLarge(params, done, resize);
      }
      return;
    }
    if (done > c.densify_from && done % c.densify_interval == 0) {
      densifyAndPrune(params, effective_opacity, done > c.opacity_reset_interval, done, resize);
    }
    if (resetsOpacitiesAfter(c, c, done)) {
      Parameter& o = params["opacity"];
      o.value.clamp_max_(logit(0.01));
      o.m.zero_();
      o.v.zero_();
    }
  }

  void resized(const RowChange& change) override {
    grad_accum_ = change.apply(grad_accum_, 0);
    denom_ = change.apply(denom_, 0);
    max_radii_ = change.apply(max_radii_, 0);
  }

  void save(TensorArchive& a) const override {
    a.tensors["grad_accum"] = grad_accum_;
    a.tensors["denom"] = denom_;
    a.tensors["max_radii"] = max_radii_;
  }

  void load(const TensorArchive& a, const std::string& path, const at::Device& device) override {
    grad_accum_ = a.tensor("grad_accum", path).to(device);
    denom_ = a.tensor("denom", path).to(device);
    max_radii_ = a.tensor("max_radii", path).to(device);
  }

  void checkRows(std::int64_t rows) const override {
    requireRows(grad_accum_, "grad_accum", rows);
    requireRows(denom_, "denom", rows);
    requireRows(max_radii_, "max_radii", rows);
  }

  std::vector<std::string> rowTensors() const override {
    return {"grad_accum", "denom", "max_radii"};
  }

 private:
  void densifyAndPrune(ParameterStore& params, const std::function<at::Tensor()>& effective_opacity,
                       bool prune_big, int iteration, const Resize& resize) {
    const Settings& c = config_;
    const at::Tensor avg = grad_accum_ / denom_.clamp_min(1);
    const at::Tensor scales = params["scales"].value.detach().exp();
    const at::Tensor max_scale = std::get<0>(scales.max(1));
    const at::Tensor big_grad = avg >= c.densify_grad_threshold;
    const double dense = c.percent_dense * extent_;
    const bool room = params.rows() < c.max_gaussians;
    const at::Tensor clone = room ? big_grad & (max_scale <= dense) : at::zeros_like(big_grad);
    const at::Tensor split = room ? big_grad & (max_scale > dense) : at::zeros_like(big_grad);

    const at::Tensor clone_idx = clone.nonzero().squeeze(1);
    const at::Tensor split_idx = split.nonzero().squeeze(1);
    std::map<std::string, at::Tensor> extra =
        splitRows(params, split_idx, scales, iteration, RandomPurpose::kDensifySplit);
    for (const Parameter& q : params.all()) {
      if (!q.per_gaussian) continue;
      const at::Tensor cloned = q.value.detach().index_select(0, clone_idx);
      extra[q.name] = at::cat({cloned, extra[q.name]}, 0);
    }
    // Originals of split Gaussians go; so do transparent (and, later, huge) ones. Transparent
    // means the opacity a Gaussian renders with at evaluation: times its deterministic gate.
    at::Tensor keep = split.logical_not();
    at::Tensor remove = effective_opacity() < c.min_opacity;
    if (prune_big) {
      remove = remove | (max_radii_ > c.max_screen_radius) | (max_scale > 0.1 * extent_);
    }
    keep = keep & remove.logical_not();
    resize(keep, extra);
    clearStatistics();  // the statistics start again with the new rows
  }

  // Split: two samples from each Gaussian of `idx`, scales divided by 1.6 (3DGS); the new rows
  // of every per-Gaussian parameter. `purpose` separates the random streams of the callers.
  std::map<std::string, at::Tensor> splitRows(ParameterStore& params, const at::Tensor& idx,
                                              const at::Tensor& scales, int iteration,
                                              RandomPurpose purpose) const {
    const Settings& c = config_;
    const at::Tensor s = scales.index_select(0, idx).repeat({2, 1});
    at::Generator gen = seededGenerator(c.seed, purpose, static_cast<std::uint64_t>(iteration));
    const at::Tensor noise = at::normal(0.0, 1.0, {s.size(0), 3}, gen).to(s.device()) * s;
    const at::Tensor q = params["quats"].value.detach().index_select(0, idx).repeat({2, 1});
    const at::Tensor qn = q / q.norm(2, 1, true);
    const at::Tensor w = qn.select(1, 0), x = qn.select(1, 1), y = qn.select(1, 2),
                     z = qn.select(1, 3);
    const at::Tensor R =
        at::stack({1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                   2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
                  1)
            .view({-1, 3, 3});
    const at::Tensor means = at::bmm(R, noise.unsqueeze(2)).squeeze(2) +
                             params["means"].value.detach().index_select(0, idx).repeat({2, 1});
    std::map<std::string, at::Tensor> rows;
    for (const Parameter& p : params.all()) {
      if (!p.per_gaussian) continue;
      const at::Tensor src = p.value.detach();
      std::vector<int64_t> reps(static_cast<std::size_t>(src.dim()), 1);
      reps[0] = 2;
      at::Tensor split = src.index_select(0, idx).repeat(reps);
      if (p.name == "means") split = means;
      if (p.name == "scales") split = split - std::log(1.6);
      rows[p.name] = split;
    }
    return rows;
  }

  void splitLarge(ParameterStore& params, int iteration, const Resize& resize) {
    const at::Tensor scales = params["scales"].value.detach().exp();
    const at::Tensor large = std::get<0>(scales.max(1)) > config_.large_split_scale * extent_;
    if (!large.any().item<bool>()) return;
    const at::Tensor idx = large.nonzero().squeeze(1);
    resize(large.logical_not(),
           splitRows(params, idx, scales, iteration, RandomPurpose::kLargeSplit));
    clearStatistics();
  }

  // Splits every Gaussian larger than `bound` (world units) until none is, in at most kRounds
  // rounds of 3DGS's split (each: two samples, scales / 1.6); the clamp takes what is left. The
  // split adds at most a quarter of the model's rows (and stays within max_gaussians): past that,
  // a round splits its largest Gaussians only, so a scene of huge splats cannot blow up the model.
  void splitAbove(ParameterStore& params, double bound, int iteration, const Resize& resize) {
    constexpr int kRounds = 8;
    const std::int64_t budget =
        std::min<std::int64_t>(params.rows() / 4, config_.max_gaussians - params.rows());
    std::int64_t added = 0;
    for (int round = 0; round < kRounds && added < budget; ++round) {
      const at::Tensor scales = params["scales"].value.detach().exp();
      const at::Tensor largest = std::get<0>(scales.max(1));
      const at::Tensor large = largest > bound;
      const std::int64_t count = large.sum().item<std::int64_t>();
      if (count == 0) break;
      at::Tensor split = large;
      if (count > budget - added) {  // the largest that fit: each split adds one row
        const at::Tensor top = std::get<1>(largest.topk(budget - added));
        split = at::zeros_like(large).index_fill_(0, top, true);
      }
      const at::Tensor idx = split.nonzero().squeeze(1);
      added += idx.size(0);
      resize(split.logical_not(),
             splitRows(
                 params, idx, scales, iteration,
                 static_cast<RandomPurpose>(purposeKey(RandomPurpose::kScaleLimitSplit) + round)));
    }
    clearStatistics();
  }

  // After rows change, the accumulated screen-space statistics start again.
  void clearStatistics() {
    grad_accum_.zero_();
    denom_.zero_();
    max_radii_.zero_();
  }

  // The strategy's own group and the schedule it runs in (iterations, seed).
  struct Settings : DensificationOptions, ScheduleOptions {};
  Settings config_;
  double extent_;
  at::Tensor grad_accum_, denom_, max_radii_;
  at::Tensor step_grad_, step_denom_;  // a step's sums, apart while they are all-reduced
};

// The last iteration after which a reset leaves the training room to win the opacities back: a
// third of the reset interval (1000 of 3000; from logit(0.01) an opacity needs ~150 Adam steps at
// 3DGS's learning rate to reach 0.9). Without it, densify_until = iterations with an interval
// that divides it reset every opacity to 0.01 after the last step: a model that renders nothing.
std::int64_t lastResetAllowed(const DensificationOptions& d, const ScheduleOptions& s) {
  return std::min<std::int64_t>(d.densify_until,
                                std::int64_t{s.iterations} - d.opacity_reset_interval / 3);
}

}  // namespace

bool resetsOpacitiesAfter(const DensificationOptions& d, const ScheduleOptions& s, int done) {
  return d.opacity_reset_interval > 0 && done <= lastResetAllowed(d, s) &&
         done % d.opacity_reset_interval == 0;
}

std::string describeDefaultDensification(const TrainConfig& c) {
  std::ostringstream s;
  s << c.iterations << " iterations; ";
  // Densification rounds come at the multiples of densify_interval in (densify_from, until].
  const std::int64_t first =
      (std::int64_t{c.densify_from} / c.densify_interval + 1) * c.densify_interval;
  if (first > std::min(c.densify_until, c.iterations)) {
    s << "no densification";
  } else {
    s << "densification after " << c.densify_from << " until " << c.densify_until << " every "
      << c.densify_interval;
  }
  // Resets after the multiples of opacity_reset_interval up to lastResetAllowed
  // (resetsOpacitiesAfter). Counted, not walked (64 bits: any interval, any length).
  const std::int64_t interval = c.opacity_reset_interval;
  const std::int64_t last_done = lastResetAllowed(c, c);
  const std::int64_t resets = interval > 0 && last_done > 0 ? last_done / interval : 0;
  s << "; opacity reset ";
  if (resets == 0) {
    s << "none";
  } else if (resets <= 4) {
    s << "at ";
    for (std::int64_t r = 1; r <= resets; ++r) s << (r > 1 ? ", " : "") << r * interval;
  } else {
    s << "every " << interval << " from " << interval << " to " << resets * interval;
  }
  if (c.scale_limit > 0 && c.scale_limit_from < c.iterations) {
    s << "; scale limit " << c.scale_limit << " x the extent from " << c.scale_limit_from;
  }
  return s.str();
}

DensificationStrategy::Ptr makeDefaultDensification(const DensificationOptions& options,
                                                    const ScheduleOptions& schedule,
                                                    double extent) {
  return std::make_shared<DefaultDensification>(options, schedule, extent);
}

}  // namespace gaussians
}  // namespace sadsplat
