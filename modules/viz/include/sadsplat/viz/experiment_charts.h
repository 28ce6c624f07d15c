#pragma once
/// \file experiment_charts.h
/// \brief The compactness-quality frontier of an experiment folder as PNG charts (`sadsplat table
/// RESULTS --plots DIR`): every configuration on every scene as one point, x = how many times
/// fewer Gaussians than the baseline, y = the change of PSNR (frontier_psnr.png) or mIoU
/// (frontier_miou.png) against the baseline on the same scene, means over the training seeds.
/// An optional target region (at least `goal_fewer` times fewer, at most `goal_psnr_loss` dB
/// below, mIoU not below) is drawn as grey lines.

#include <string>
#include <vector>

#include "sadsplat/eval/experiment_table.h"

namespace sadsplat {
namespace viz {

/// \brief Where the frontier should reach; goal_fewer <= 0 draws no target.
struct FrontierGoal {
  double goal_fewer = 0;
  double goal_psnr_loss = 0;
};

/// \brief Writes DIR/frontier_psnr.png and DIR/frontier_miou.png; returns their paths.
/// \throws sadsplat::Error when there are no points (no scene has baseline runs) or no display
std::vector<std::string> writeFrontierCharts(const std::string& dir,
                                             const std::vector<eval::FrontierPoint>& points,
                                             const std::string& baseline,
                                             const FrontierGoal& goal = {});

}  // namespace viz
}  // namespace sadsplat
