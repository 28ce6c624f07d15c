#include "sadsplat/gaussians/parameter_store.h"

#include <stdexcept>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/adam.h"

namespace sadsplat {
namespace gaussians {

at::Tensor RowChange::apply(const at::Tensor& t, double fill) const {
  at::Tensor rows = t.index_select(0, kept);
  if (added == 0) return rows;
  std::vector<std::int64_t> shape(t.sizes().begin(), t.sizes().end());
  shape[0] = added;
  return at::cat({rows, at::full(shape, fill, t.options())}, 0);
}

void ParameterStore::add(const std::string& name, const at::Tensor& value, double lr,
                         bool per_gaussian, bool steps_without_gradient) {
  Parameter q;
  q.name = name;
  q.value = value.detach().clone().contiguous().requires_grad_(true);
  q.m = at::zeros_like(q.value);
  q.v = at::zeros_like(q.value);
  q.lr = lr;
  q.per_gaussian = per_gaussian;
  q.steps_without_gradient = steps_without_gradient;
  params_.push_back(q);
}

Parameter& ParameterStore::operator[](const std::string& name) {
  for (auto& q : params_) {
    if (q.name == name) return q;
  }
  throw Error("<trainer>", name, "a known parameter", "no parameter of that name");
}

const Parameter& ParameterStore::operator[](const std::string& name) const {
  return const_cast<ParameterStore&>(*this)[name];
}

GaussianParams ParameterStore::gaussians() const {
  GaussianParams g;
  g.means = (*this)["means"].value;
  g.quats = (*this)["quats"].value;
  g.log_scales = (*this)["scales"].value;
  g.opacity_logits = (*this)["opacity"].value;
  g.sh = (*this)["sh_dc"].value;  // the two parts as they are stored: no copy per render
  g.sh_rest = (*this)["sh_rest"].value;
  g.features = (*this)["features"].value;
  return g;
}

RowChange ParameterStore::resize(const at::Tensor& keep,
                                 const std::map<std::string, at::Tensor>& extra) {
  RowChange change;
  change.kept = keep.nonzero().squeeze(1);
  change.added = extra.empty() ? 0 : extra.begin()->second.size(0);
  for (Parameter& q : params_) {
    if (!q.per_gaussian) continue;
    at::Tensor value = q.value.detach().index_select(0, change.kept);
    at::Tensor m = q.m.index_select(0, change.kept), v = q.v.index_select(0, change.kept);
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
  return change;
}

void ParameterStore::adamStep() {
  // Adam (own, fused implementation so densification can reshape its state).
  ++adam_step_;
  std::vector<AdamTensors> step;
  for (Parameter& q : params_) {
    const at::Tensor grad = q.value.grad();
    if (!grad.defined() && !q.steps_without_gradient) continue;
    step.push_back({q.value, grad, q.m, q.v, q.lr});  // holds the gradient for adamSteps
    if (grad.defined()) q.value.mutable_grad().reset();
  }
  gaussians::adamSteps(step, adam_step_);  // one launch on CUDA
}

void ParameterStore::allReduceGradients(Collective& collective,
                                        const std::function<bool(const Parameter&)>& anywhere,
                                        const std::vector<at::Tensor*>& sums) {
  std::vector<at::Tensor> parts;
  std::vector<Parameter*> sent;
  for (Parameter& q : params_) {
    const at::Tensor grad = q.value.grad();
    const bool somewhere = anywhere(q);
    if (grad.defined() && !somewhere) {
      throw std::logic_error("trainer: gradient of " + q.name + " outside the global batch");
    }
    if (!somewhere) continue;
    parts.push_back(grad.defined() ? grad.reshape({-1})
                                   : at::zeros({q.value.numel()}, q.value.options()));
    sent.push_back(&q);
  }
  for (at::Tensor* sum : sums) parts.push_back(sum->reshape({-1}));
  at::Tensor flat = at::cat(parts);
  collective.sum(flat);
  std::int64_t offset = 0;
  for (Parameter* q : sent) {
    const std::int64_t n = q->value.numel();
    q->value.mutable_grad() = flat.slice(0, offset, offset + n).view(q->value.sizes());
    offset += n;
  }
  for (at::Tensor* sum : sums) {
    const std::int64_t n = sum->numel();
    *sum = flat.slice(0, offset, offset + n).view(sum->sizes());
    offset += n;
  }
}

void ParameterStore::save(TensorArchive& a) const {
  for (const Parameter& q : params_) {
    a.tensors[q.name] = q.value.detach();
    a.tensors[q.name + ".m"] = q.m;
    a.tensors[q.name + ".v"] = q.v;
  }
  a.numbers["adam_step"] = static_cast<double>(adam_step_);
}

void ParameterStore::load(const TensorArchive& a, const std::string& path,
                          const at::Device& device) {
  for (Parameter& q : params_) {
    const at::Tensor& value = a.tensor(q.name, path);
    if (!q.per_gaussian && !value.sizes().equals(q.value.sizes())) {
      throw Error(path, "tensor " + q.name, "the shape of this configuration's " + q.name,
                  "another shape");
    }
    q.value = value.to(device).contiguous().requires_grad_(true);
    q.m = a.tensor(q.name + ".m", path).to(device).contiguous();
    q.v = a.tensor(q.name + ".v", path).to(device).contiguous();
  }
  adam_step_ = static_cast<std::int64_t>(a.number("adam_step", path));
}

void requireRows(const at::Tensor& t, const std::string& name, std::int64_t rows) {
  if (!t.defined() || t.size(0) != rows) {
    throw Error("<trainer>", name, std::to_string(rows) + " rows",
                t.defined() ? std::to_string(t.size(0)) : "undefined");
  }
}

void ParameterStore::checkRows() const {
  for (const Parameter& q : params_) {
    if (!q.per_gaussian) continue;
    requireRows(q.value, q.name, rows());
    requireRows(q.m, q.name + " Adam m", rows());
    requireRows(q.v, q.name + " Adam v", rows());
  }
}

std::vector<std::string> ParameterStore::rowTensors() const {
  std::vector<std::string> names;
  for (const Parameter& q : params_) {
    if (!q.per_gaussian) continue;
    names.insert(names.end(), {q.name, q.name + ".m", q.name + ".v"});
  }
  return names;
}

}  // namespace gaussians
}  // namespace sadsplat
