#pragma once
/// \file parameter_store.h
/// \brief The trainer's optimised tensors and their Adam moments: the one place the Gaussians'
/// rows change (densification, drops, pruning), so that every per-row tensor stays in step.

#include <ATen/ATen.h>

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "sadsplat/gaussians/collective.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/tensor_archive.h"

namespace sadsplat {
namespace gaussians {

/// \brief Which rows a resize kept (in order) and how many it appended after them. Applied to
/// every other per-Gaussian tensor (statistics, gate state) with its fill value for new rows.
struct RowChange {
  at::Tensor kept;          ///< [M] int64 indices of the kept rows
  std::int64_t added = 0;  ///< rows appended after the kept ones
  /// \brief `t`'s kept rows, then `added` rows of `fill`.
  at::Tensor apply(const at::Tensor& t, double fill) const;
};

/// \brief Throws naming `name` unless `t` is defined with `rows` rows: the consistency check of
/// every per-row state that follows the parameters.
void requireRows(const at::Tensor& t, const std::string& name, std::int64_t rows);

/// \brief One optimised tensor with its Adam moments.
struct Parameter {
  std::string name;
  at::Tensor value, m, v;
  double lr = 0;
  bool per_gaussian = true;  ///< one row per Gaussian (resized with them)
  /// Takes an Adam step with a zero gradient when no view rendered it (the semantic features:
  /// their momentum carries on, as when they were rendered and got zero gradient).
  bool steps_without_gradient = false;
};

/// \brief The parameters in a fixed order, with one Adam step counter.
class ParameterStore {
 public:
  /// \brief Adds a parameter (a detached, contiguous copy of `value` that requires grad).
  void add(const std::string& name, const at::Tensor& value, double lr, bool per_gaussian = true,
           bool steps_without_gradient = false);
  Parameter& operator[](const std::string& name);
  const Parameter& operator[](const std::string& name) const;
  std::vector<Parameter>& all() { return params_; }
  const std::vector<Parameter>& all() const { return params_; }
  /// \brief Number of Gaussians (rows of the first parameter).
  std::int64_t rows() const { return params_.front().value.size(0); }

  /// \brief Render-ready parameters (no gate).
  GaussianParams gaussians() const;

  /// \brief Keeps the rows where `keep` is true, then appends `extra` rows (per parameter name;
  /// their Adam moments start at zero).
  RowChange resize(const at::Tensor& keep, const std::map<std::string, at::Tensor>& extra);

  /// \brief One Adam step of every parameter that has a gradient (or steps without one); the
  /// gradients are reset.
  void adamStep();

  /// \brief Sums every parameter's gradient and the tensors `sums` over the ranks in one flat
  /// all-reduce, without a host synchronisation. `anywhere(p)` says whether any rank has p's
  /// gradient this step: one that no rank has stays undefined and is not sent; one that only
  /// some ranks have counts as zero on the others.
  /// \throws std::logic_error when a rank has a gradient `anywhere` denies
  void allReduceGradients(Collective& collective,
                          const std::function<bool(const Parameter&)>& anywhere,
                          const std::vector<at::Tensor*>& sums);

  /// \brief Writes values, moments and the step counter into `archive`.
  void save(TensorArchive& archive) const;
  /// \brief Restores them onto `device`.
  /// \throws sadsplat::Error naming `path` when a tensor is missing or misshapen
  void load(const TensorArchive& archive, const std::string& path, const at::Device& device);
  /// \brief Throws unless every per-row tensor has `rows()` rows.
  void checkRows() const;
  /// \brief The archive names (save) of the per-row tensors: values and moments.
  std::vector<std::string> rowTensors() const;

 private:
  std::vector<Parameter> params_;
  std::int64_t adam_step_ = 0;
};

}  // namespace gaussians
}  // namespace sadsplat
