#pragma once
/// \file l0_force.h
/// \brief The balanced drop rule's L0 force, added to the gradient of the gates' log_alpha after
/// the backward pass. Over the Gaussians the losses reached this step (opacity gradient != 0) the
/// force's mean equals `strength` times the mean |loss gradient| of log_alpha:
///
///     grad += direction * reached * strength * sum(|grad| * reached) / sum(direction * reached)
///             [* weights]
///
/// (no force when sum(direction * reached) is 0). On CUDA (float32) two kernels do it in place
/// (the two sums, then the update); elsewhere the same arithmetic as ATen operations.

#include <ATen/ATen.h>

namespace sadsplat {
namespace semantic_drop {

/// \brief Adds the force to `grad` in place.
/// \param[in,out] grad [N] float gradient of log_alpha
/// \param[in] direction [N] the L0 term's derivative by log_alpha (>= 0)
/// \param[in] opacity_grad [N] gradient of the opacity logits (0: the losses did not reach it)
/// \param[in] weights [N] per-Gaussian factors of the force, or undefined (all 1)
/// \param[in] strength the force's mean relative to the mean |loss gradient|
void addBalancedL0Force(at::Tensor& grad, const at::Tensor& direction,
                        const at::Tensor& opacity_grad, const at::Tensor& weights, double strength);

/// \brief The same as ATen operations on any device (the reference the kernels are tested
/// against).
void addBalancedL0ForceReference(at::Tensor& grad, const at::Tensor& direction,
                                 const at::Tensor& opacity_grad, const at::Tensor& weights,
                                 double strength);

}  // namespace semantic_drop
}  // namespace sadsplat
