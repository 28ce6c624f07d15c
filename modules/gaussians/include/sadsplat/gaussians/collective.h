#pragma once
/// \file collective.h
/// \brief What the trainer needs from data-parallel ranks: its rank, the rank count and in-place
/// sums / maxima of tensors over all ranks. The module `distributed` implements it on LibTorch's
/// c10d process groups; the trainer runs without one (a single process).

#include <ATen/ATen.h>

#include <memory>

namespace sadsplat {
namespace gaussians {

/// \brief Collective operations over the ranks of one training.
class Collective {
 public:
  using Ptr = std::shared_ptr<Collective>;
  virtual ~Collective() = default;
  /// \brief This process's rank, 0 .. size() - 1.
  virtual int rank() const = 0;
  /// \brief The number of ranks.
  virtual int size() const = 0;
  /// \brief Replaces `tensor` (contiguous) on every rank by its element-wise sum over the ranks.
  /// \throws sadsplat::Error when a rank does not answer in time
  virtual void sum(at::Tensor& tensor) = 0;
  /// \brief Replaces `tensor` (contiguous) on every rank by its element-wise maximum.
  virtual void max(at::Tensor& tensor) = 0;
};

}  // namespace gaussians
}  // namespace sadsplat
