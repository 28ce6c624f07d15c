#include "sadsplat/semantic_drop/drop_strategy.h"

#include <algorithm>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/counter_random.h"
#include "sadsplat/semantic_drop/semantic_confidence.h"

namespace sadsplat {
namespace semantic_drop {
namespace {

class SemanticDropStrategy : public gaussians::DropStrategy {
 public:
  SemanticDropStrategy(const gaussians::TrainConfig& c, bool semantic, bool structure,
                       const HardConcreteParams& hc)
      : semantic_(semantic),
        structure_(structure),
        p_base_(c.p_base),
        interval_(c.drop_interval),
        iterations_(c.iterations),
        lambda_l0_(c.lambda_l0),
        lambda_l0_from_(c.lambda_l0_from),
        lambda_l0_ramp_(c.lambda_l0_ramp),
        seed_(c.seed),
        balanced_(gaussians::balancedDropRule(c)),
        closed_gate_gradients_(c.closed_gate_gradients),
        hc_(hc) {}

  at::Tensor l0Derivative(const at::Tensor& log_alpha) const override {
    if (!structure_) return {};
    // P_nonzero = sigmoid(log_alpha - beta logit(t)) (hard_concrete_math.h): dP = P (1 - P).
    const at::Tensor p = probabilityNonZero(log_alpha.detach(), hc_);
    return p * (1 - p);
  }

  at::Tensor trainingGate(const at::Tensor& log_alpha, int iteration) const override {
    if (!structure_) return {};
    // Counter-based noise on the parameters' device: nothing drawn on the host and copied.
    return sampleCounterGate(log_alpha, seed_,
                             gaussians::purposeKey(gaussians::RandomPurpose::kGateNoise),
                             static_cast<std::uint64_t>(iteration), hc_, closed_gate_gradients_);
  }

  at::Tensor evaluationGate(const at::Tensor& log_alpha) const override {
    return structure_ ? deterministicGate(log_alpha, hc_) : at::Tensor();
  }

  at::Tensor regularisation(const at::Tensor& log_alpha, int iteration,
                            const at::Tensor& l0_weights) const override {
    // L_L0 = mean over Gaussians of P_nonzero (paper), weighted by lambda_L0 (or its schedule);
    // with per-Gaussian weights (not the paper) the mean of weight x P_nonzero.
    const double weight =
        scheduledL0Weight(lambda_l0_, lambda_l0_from_, lambda_l0_ramp_, iteration);
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
    return interval_ > 0 && done % interval_ == 0 && done < iterations_;
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
    at::Tensor p_drop = at::full_like(confidence, p_base_);
    if (semantic_) p_drop = p_drop * (1 - confidence);
    if (structure_) p_drop = p_drop * (1 - p_nonzero);
    p_drop = p_drop.clamp(0, 1);
    at::Generator gen = gaussians::seededGenerator(seed_, gaussians::RandomPurpose::kDropSample,
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
  bool semantic_, structure_;
  double p_base_;
  int interval_, iterations_;
  double lambda_l0_;
  int lambda_l0_from_, lambda_l0_ramp_;
  std::uint64_t seed_;
  bool balanced_;
  bool closed_gate_gradients_;
  HardConcreteParams hc_;
};

}  // namespace

double scheduledL0Weight(double lambda, int from, int ramp, int iteration) {
  return lambda * gaussians::l0Ramp(from, ramp, iteration);
}

std::shared_ptr<const gaussians::DropStrategy> makeDropStrategy(const gaussians::TrainConfig& c,
                                                                const HardConcreteParams& hc) {
  c.check();  // ranges and choices of every option, the drop's included
  if (c.drop == "none") return nullptr;
  if (c.drop == "semantic") return std::make_shared<SemanticDropStrategy>(c, true, false, hc);
  if (c.drop == "structure") return std::make_shared<SemanticDropStrategy>(c, false, true, hc);
  if (c.drop == "full") return std::make_shared<SemanticDropStrategy>(c, true, true, hc);
  throw Error("<config>", "drop", "none, semantic, structure or full", c.drop);
}

}  // namespace semantic_drop
}  // namespace sadsplat
