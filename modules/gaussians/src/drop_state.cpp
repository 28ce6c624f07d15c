#include "drop_state.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <tuple>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/contribution.h"

namespace sadsplat {
namespace gaussians {
namespace {

// log_alpha of a gate folded into its opacity: sigmoid(20) * 1.2 - 0.1 > 1, so the deterministic
// gate is exactly 1, and so is every training sample (the noise's logit is clamped to +-13.8).
constexpr double kSettledLogAlpha = 20.0;

}  // namespace

void DropState::initialise(std::int64_t rows, const at::TensorOptions& options) {
  confidence_ = at::zeros({rows}, options);
  l0_weights_ = at::ones({rows}, options);
}

int DropState::recoveryStart() const {
  return options_.recovery_iterations > 0 ? schedule_.iterations - options_.recovery_iterations
                                          : schedule_.iterations + 1;
}

at::Tensor DropState::evaluationGate(const ParameterStore& params, int iteration) const {
  return gated(iteration) ? drop_->evaluationGate(params["log_alpha"].value.detach())
                          : at::Tensor();
}

at::Tensor DropState::trainingGate(const ParameterStore& params, int it) const {
  return gated(it) ? drop_->trainingGate(params["log_alpha"].value, it) : at::Tensor();
}

at::Tensor DropState::effectiveOpacity(const ParameterStore& params, int iteration) const {
  const at::Tensor opacity = at::sigmoid(params["opacity"].value.detach());
  const at::Tensor gate = evaluationGate(params, iteration);
  return gate.defined() ? opacity * gate : opacity;
}

at::Tensor DropState::regularisation(const ParameterStore& params, int it) const {
  if (!gated(it)) return at::Tensor();
  return drop_->regularisation(params["log_alpha"].value, it,
                               options_.l0_importance > 0 ? l0_weights_ : at::Tensor());
}

void DropState::addL0Gradient(ParameterStore& params, int it) const {
  if (!gated(it)) return;
  Parameter& la = params["log_alpha"];
  at::Tensor grad = la.value.grad();
  const at::Tensor opacity_grad = params["opacity"].value.grad();
  if (!grad.defined() || !opacity_grad.defined()) return;
  drop_->addL0Force(grad, la.value, opacity_grad,
                    options_.l0_importance > 0 ? l0_weights_ : at::Tensor(), it, guard_);
}

bool DropState::guardProbeDue(int done) const {
  return drop_ && done < recoveryStart() && drop_->guardReadsBefore(done);
}

void DropState::observeGuardProbe(int done, double probe_mse) {
  if (drop_) drop_->observeGuardReading(guard_, done, probe_mse);
}

bool DropState::refreshesL0Weights(int it) const {
  return gated(it) && options_.l0_importance > 0 && options_.drop_interval > 0 &&
         it >= options_.lambda_l0_from &&
         (it - options_.lambda_l0_from) % options_.drop_interval == 0;
}

void DropState::refreshL0Weights(const ParameterStore& params, const TrainingViews& views,
                                 int iteration) {
  GaussianParams g = params.gaussians();
  g.opacity_gate = evaluationGate(params, iteration);
  l0_weights_ = inverseContributionWeights(blendingWeightSums(g, views.trainingCameras()),
                                           options_.l0_importance);
}

DropDecision DropState::dropIfDue(int done, const ParameterStore& params,
                                  const TrainingViews& views, const Resize& resize,
                                  std::int64_t* dropped) {
  DropDecision decision;
  if (!drop_->dropNow(done)) return decision;
  DropInputs in;
  in.max_removed = drop_->maxRemoved(params.rows(), guard_);
  in.means = params["means"].value.detach();
  in.opacities = at::sigmoid(params["opacity"].value.detach());
  in.log_alpha = params["log_alpha"].value.detach();
  for (int v : views.train_views) {
    if (!views.confidence_maps[v].defined()) continue;
    in.cameras.push_back(views.cameras[v]);
    in.confidence_maps.push_back(views.confidence_maps[v]);
  }
  decision = drop_->decide(in, done);
  confidence_ = decision.confidence.to(confidence_.device()).to(at::kFloat);
  *dropped = params.rows() - decision.keep.sum().item<std::int64_t>();
  resize(decision.keep.to(confidence_.device()), {});
  return decision;
}

std::pair<std::int64_t, std::int64_t> DropState::settleGates(ParameterStore& params,
                                                             const TrainingViews& views,
                                                             const Resize& resize) {
  std::int64_t closed = 0, pruned = 0;
  const at::Tensor gate =
      drop_ ? drop_->evaluationGate(params["log_alpha"].value.detach()) : at::Tensor();
  if (gate.defined()) {
    const at::Tensor open = gate > 0;
    closed = params.rows() - open.sum().item<std::int64_t>();
    resize(open, {});
    const at::Tensor kept_gate = gate.index_select(0, open.nonzero().squeeze(1));
    Parameter& o = params["opacity"];
    const at::Tensor folded = (at::sigmoid(o.value.detach()) * kept_gate).clamp(1e-6, 1 - 1e-6);
    o.value = at::logit(folded).contiguous().requires_grad_(true);
    Parameter& la = params["log_alpha"];
    la.value = at::full_like(la.value.detach(), kSettledLogAlpha).requires_grad_(true);
    la.m.zero_();
    la.v.zero_();
  }
  if (options_.recovery_prune > 0 && params.rows() > 0) {
    const at::Tensor score = blendingWeightSums(params.gaussians(), views.trainingCameras());
    const std::int64_t count = static_cast<std::int64_t>(
        std::floor(options_.recovery_prune * static_cast<double>(params.rows())));
    if (count > 0) {
      // The `count` lowest scores go (ties by index: a stable sort keeps this deterministic).
      const at::Tensor order = std::get<1>(score.sort(/*stable=*/true, 0, false));
      at::Tensor keep = at::ones({params.rows()}, score.options().dtype(at::kBool));
      keep.index_fill_(0, order.narrow(0, 0, count), false);
      pruned = count;
      resize(keep, {});
    }
  }
  return {closed, pruned};
}

std::int64_t DropState::removeClosedGates(const ParameterStore& params, int iteration,
                                          const Resize& resize) {
  const at::Tensor gate = evaluationGate(params, iteration);
  if (!gate.defined()) return 0;
  const at::Tensor open = gate > 0;
  const std::int64_t closed = params.rows() - open.sum().item<std::int64_t>();
  if (closed > 0) resize(open, {});
  return closed;
}

void DropState::resized(const RowChange& change) {
  confidence_ = change.apply(confidence_, 0);
  l0_weights_ = change.apply(l0_weights_, 1);
}

void DropState::save(TensorArchive& a) const {
  a.tensors["confidence"] = confidence_;
  a.tensors["l0_weights"] = l0_weights_;
  // The archive stores no doubles: their bits as int64, so that a resumed run continues exactly.
  const std::array<double, 4> packed = guard_.packed();
  std::vector<std::int64_t> bits(packed.size());
  std::memcpy(bits.data(), packed.data(), sizeof(double) * packed.size());
  a.tensors["drop_guard"] = at::tensor(bits, at::kLong);
}

void DropState::load(const TensorArchive& a, const std::string& path, const at::Device& device) {
  confidence_ = a.tensor("confidence", path).to(device);
  // Checkpoints written before the importance-weighted L0 have no weights: the plain mean's.
  l0_weights_ = a.tensors.count("l0_weights") ? a.tensor("l0_weights", path).to(device)
                                              : at::ones_like(confidence_);
  // Checkpoints written before the balanced rule have no guard state: a fresh guard.
  guard_ = DropGuard();
  if (a.tensors.count("drop_guard")) {
    const at::Tensor g = a.tensor("drop_guard", path).to(at::kCPU).contiguous();
    if (g.numel() != 4 || g.scalar_type() != at::kLong) {
      throw Error(path, "drop_guard", "4 int64 values (the guard's doubles)",
                  std::to_string(g.numel()) + " values of " + std::string(g.dtype().name()));
    }
    std::array<double, 4> packed{};
    std::memcpy(packed.data(), g.data_ptr<std::int64_t>(), sizeof(double) * packed.size());
    if (!(packed[0] > 0 && packed[0] <= 1)) {
      throw Error(path, "drop_guard pressure", "a value in (0, 1]", std::to_string(packed[0]));
    }
    guard_ = DropGuard::unpacked(packed);
  }
}

void DropState::checkRows(std::int64_t rows) const {
  requireRows(confidence_, "confidence", rows);
  requireRows(l0_weights_, "l0_weights", rows);
}

}  // namespace gaussians
}  // namespace sadsplat
