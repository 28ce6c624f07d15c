#pragma once
/// \file drop_strategy.h
/// \brief The semantic-aware drop during training (paper, "Gaussian Point Drop"): Hard Concrete
/// gates on the opacity, the L0 term, and every N iterations the removal of each Gaussian with
/// probability P_drop = clamp(P_base (1 - P_conf) P_learned, 0, 1). Under the balanced rule
/// (DropOptions::drop_rule, the default) also the L0 force in place of the term, the cap on each
/// event and the quality guard (docs/GUIDE.md, "The drop rule").

#include <memory>

#include "sadsplat/gaussians/drop_strategy.h"
#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/semantic_drop/hard_concrete.h"

namespace sadsplat {
namespace semantic_drop {

/// \brief The factor of the L0 schedule in (0-based) `iteration`: 0 before `from`, then rising
/// linearly to 1 over `ramp` iterations (ramp 0: 1 at once). The L0 weight of the paper's rule
/// and the L0 force of the balanced rule both follow it (DropOptions::lambda_l0_from / _ramp).
double l0Ramp(int from, int ramp, int iteration);

/// \brief The weight of L_L0 in (0-based) `iteration`: 0 before `from`, then rising linearly to
/// `lambda` over `ramp` iterations (ramp 0: `lambda` at once; from 0, ramp 0: the paper's
/// constant weight).
double scheduledL0Weight(double lambda, int from, int ramp, int iteration);

/// \brief The strategy for `config.drop` (none | semantic | structure | full), or nullptr for
/// none. "semantic" uses only P_conf, "structure" only the gates (P_learned and L0), "full" both.
/// Until pseudo-label confidence maps exist, P_conf comes from one-hot maps of the labelled
/// views, so a Gaussian seen in none of them has P_conf = 0.
/// \throws sadsplat::Error on a negative P_base / interval / L0 schedule
std::shared_ptr<const gaussians::DropStrategy> makeDropStrategy(
    const gaussians::TrainConfig& config, const HardConcreteParams& hc = {});

}  // namespace semantic_drop
}  // namespace sadsplat
