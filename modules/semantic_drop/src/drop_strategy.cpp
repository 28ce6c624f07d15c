#include "sadsplat/semantic_drop/drop_strategy.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/counter_random.h"
#include "sadsplat/gaussians/densification.h"
#include "sadsplat/gaussians/schedule.h"
#include "sadsplat/semantic_drop/l0_force.h"
#include "sadsplat/semantic_drop/semantic_confidence.h"

namespace sadsplat {
namespace semantic_drop {
namespace {

// The paper's rule, or the balanced one (DropOptions::drop_rule): the L0 force in place of the
// loss term, a cap on each event, the guard, no event before the L0 force starts.
class SemanticDropStrategy : public gaussians::DropStrategy {
 public:
  SemanticDropStrategy(const gaussians::TrainConfig& c, bool semantic, bool structure,
                       const HardConcreteParams& hc)
      : options_(c),
        schedule_(c),
        densification_(c),
        semantic_(semantic),
        structure_(structure),
        balanced_(c.drop_rule == gaussians::DropRule::kBalanced),
        hc_(hc) {}

  void addL0Force(at::Tensor& grad, const at::Tensor& log_alpha, const at::Tensor& opacity_grad,
                  const at::Tensor& l0_weights, int it,
                  const gaussians::DropGuard& guard) const override {
    if (!balanced_) return;
    // The L0 schedule (lambda_l0_from, lambda_l0_ramp) applies to the strength as to lambda_l0.
    if (it < options_.lambda_l0_from) return;
    const double strength = options_.l0_strength * guard.pressure *
                            l0Ramp(options_.lambda_l0_from, options_.lambda_l0_ramp, it);
    if (strength == 0 || !structure_) return;
    // The force's direction: d P_nonzero / d log_alpha; P_nonzero = sigmoid(log_alpha - beta
    // logit(t)) (hard_concrete_math.h), so dP = P (1 - P). The Gaussians the losses reached this
    // step are those whose opacity has a gradient (all-reduced, so every rank sees the same set):
    // a gate sample clamped at 1 gives log_alpha no gradient, but the L0 force acts on it as in
    // the paper's rule.
    const at::Tensor p = probabilityNonZero(log_alpha.detach(), hc_);
    addBalancedL0Force(grad, p * (1 - p), opacity_grad, l0_weights, strength);
  }

  std::int64_t maxRemoved(std::int64_t rows, const gaussians::DropGuard& guard) const override {
    if (!balanced_) return -1;
    return static_cast<std::int64_t>(
        std::floor(options_.drop_max_fraction * guard.pressure * static_cast<double>(rows)));
  }

  bool guardReadsBefore(int done) const override {
    return balanced_ && options_.drop_guard > 0 && dropNow(done);
  }

  void observeGuardReading(gaussians::DropGuard& guard, int done,
                           double probe_mse) const override {
    if (!balanced_ || !std::isfinite(probe_mse)) return;  // the paper's rule has no guard
    // The reference is the lowest reading since the last opacity reset (a reset raises the error
    // by itself): a drop whose cost the training has not won back by the next event halves the
    // pressure again.
    const bool fresh =
        guard.lowest < 0 || openedByReset(static_cast<int>(guard.last_reading), done);
    if (!fresh && probe_mse > guard.lowest * (1 + options_.drop_guard)) guard.pressure *= 0.5;
    guard.lowest = fresh ? probe_mse : std::min(guard.lowest, probe_mse);
    guard.last_reading = done;
  }

  at::Tensor trainingGate(const at::Tensor& log_alpha, int iteration) const override {
    if (!structure_) return {};
    // Counter-based noise on the parameters' device: nothing drawn on the host and copied.
    return sampleCounterGate(log_alpha, schedule_.seed,
                             gaussians::purposeKey(gaussians::RandomPurpose::kGateNoise),
                             static_cast<std::uint64_t>(iteration), hc_,
                             options_.closed_gate_gradients);
  }

  at::Tensor evaluationGate(const at::Tensor& log_alpha) const override {
    return structure_ ? deterministicGate(log_alpha, hc_) : at::Tensor();
  }

  at::Tensor regularisation(const at::Tensor& log_alpha, int iteration,
                            const at::Tensor& l0_weights) const override {
    // L_L0 = mean over Gaussians of P_nonzero (paper), weighted by lambda_L0 (or its schedule);
    // with per-Gaussian weights (not the paper) the mean of weight x P_nonzero. The balanced
    // rule has no loss term: its force is added to the gradient (addL0Force).
    if (balanced_) return {};
    const double weight = scheduledL0Weight(options_.lambda_l0, options_.lambda_l0_from,
                                            options_.lambda_l0_ramp, iteration);
    if (!structure_ || weight == 0) return {};
    const at::Tensor p_nonzero = probabilityNonZero(log_alpha, hc_);
    if (!l0_weights.defined()) return weight * p_nonzero.mean();
    if (l0_weights.numel() != p_nonzero.numel()) {
      throw Error("<drop>", "l0_weights", std::to_string(p_nonzero.numel()) + " weights",
                  std::to_string(l0_weights.numel()));
    }
    return weight * (l0_weights.to(p_nonzero.dtype()) * p_nonzero).mean();
  }

  bool dropNow(int done) const override {
    // The balanced rule prunes late when asked: no drop event (and no guard reading) before the
    // L0 force starts, so that densification, opacity resets and the semantic factor alone
    // remove nothing before it (the paper's rule drops from the start).
    if (balanced_ && done < options_.lambda_l0_from) return false;
    return options_.drop_interval > 0 && done % options_.drop_interval == 0 &&
           done < schedule_.iterations;
  }

  gaussians::DropDecision decide(const gaussians::DropInputs& in, int done) const override {
    const auto opts = in.means.options();
    at::Tensor confidence = at::zeros({in.means.size(0)}, opts);
    at::Tensor seen = at::zeros({in.means.size(0)}, opts.dtype(at::kBool));
    if (semantic_ && !in.cameras.empty()) {
      confidence =
          semanticConfidence(in.means, in.opacities, in.cameras, in.confidence_maps, &seen);
    }
    if (semantic_ && balanced_) {
      // No map saw it: unknown, not ambiguous. It takes the mean confidence of the Gaussians the
      // maps saw, and 0.5 when no map saw any (a scene without labels or pseudo-labels).
      const at::Tensor n_seen = seen.sum();
      const at::Tensor mean_seen = at::where(
          n_seen > 0, (confidence * seen).sum() / n_seen.clamp_min(1).to(confidence.dtype()),
          at::full({}, 0.5, confidence.options()));
      confidence = at::where(seen, confidence, mean_seen.expand_as(confidence));
    }
    const at::Tensor p_nonzero = probabilityNonZero(in.log_alpha, hc_);
    at::Tensor p_drop = at::full_like(confidence, options_.p_base);
    if (semantic_) p_drop = p_drop * (1 - confidence);
    if (structure_) p_drop = p_drop * (1 - p_nonzero);
    p_drop = p_drop.clamp(0, 1);
    at::Generator gen = gaussians::seededGenerator(schedule_.seed,
                                                   gaussians::RandomPurpose::kDropSample,
                                                   static_cast<std::uint64_t>(done));
    const at::Tensor u =
        at::empty({in.means.size(0)}, at::TensorOptions().dtype(opts.dtype().toScalarType()))
            .uniform_(0, 1, gen)
            .to(in.means.device());
    gaussians::DropDecision d;
    d.keep = u >= p_drop;
    if (in.max_removed >= 0) {
      const at::Tensor removed_now = d.keep.logical_not();
      const std::int64_t n = removed_now.sum().item<std::int64_t>();
      if (n > in.max_removed) {
        // Of the drawn ones, those of highest P_drop go (a stable sort: ties by index).
        const at::Tensor drawn = removed_now.nonzero().squeeze(1);
        const at::Tensor order =
            std::get<1>(p_drop.index_select(0, drawn).sort(/*stable=*/true, 0, true));
        const at::Tensor spared =
            drawn.index_select(0, order.narrow(0, in.max_removed, n - in.max_removed));
        d.keep.index_fill_(0, spared, true);
      }
    }
    d.confidence = confidence;
    d.p_drop = p_drop;
    const at::Tensor removed = d.keep.logical_not();
    d.removed = removed.sum().item<std::int64_t>();
    if (semantic_) {
      d.removed_low_confidence = (removed & (confidence < 0.5)).sum().item<std::int64_t>();
      d.removed_unseen = (removed & seen.logical_not()).sum().item<std::int64_t>();
    }
    if (structure_)
      d.removed_closed_gate = (removed & (p_nonzero < 0.5)).sum().item<std::int64_t>();
    return d;
  }

 private:
  // Whether an opacity reset came between the guard's readings after `from` and `to`: a reset
  // after iteration r comes after the drop event of r and so after its reading, so the resets
  // after from .. to - 1.
  bool openedByReset(int from, int to) const {
    for (int r = from; r < to; ++r) {
      if (gaussians::resetsOpacitiesAfter(densification_, schedule_, r)) return true;
    }
    return false;
  }

  gaussians::DropOptions options_;
  gaussians::ScheduleOptions schedule_;
  gaussians::DensificationOptions densification_;  // for its opacity resets (the guard)
  bool semantic_, structure_;
  bool balanced_;
  HardConcreteParams hc_;
};

}  // namespace

double l0Ramp(int from, int ramp, int iteration) {
  if (iteration < from) return 0;
  if (ramp <= 0) return 1;
  return std::min(1.0, static_cast<double>(iteration - from + 1) / ramp);
}

double scheduledL0Weight(double lambda, int from, int ramp, int iteration) {
  return lambda * l0Ramp(from, ramp, iteration);
}

std::shared_ptr<const gaussians::DropStrategy> makeDropStrategy(
    const gaussians::TrainConfig& config, const HardConcreteParams& hc) {
  config.check();  // ranges and choices of every option, the drop's included
  // The guard needs the opacity resets, so the densification keys whose -1 derives from the
  // iterations are resolved (as the trainer resolves them; resolving twice changes nothing).
  const gaussians::TrainConfig c = gaussians::resolveDerivedKeys(config);
  using gaussians::DropMode;
  if (c.drop == DropMode::kNone) return nullptr;
  const bool semantic = c.drop == DropMode::kSemantic || c.drop == DropMode::kFull;
  const bool structure = c.drop == DropMode::kStructure || c.drop == DropMode::kFull;
  return std::make_shared<SemanticDropStrategy>(c, semantic, structure, hc);
}

}  // namespace semantic_drop
}  // namespace sadsplat
