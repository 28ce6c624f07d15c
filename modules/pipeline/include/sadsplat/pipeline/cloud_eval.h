#pragma once
/// \file cloud_eval.h
/// \brief `sadsplat eval RUN --3d`: the per-class cloud a run hands to PCL (model_semantic's
/// Gaussians: centre, class, opacity) scored against the world of a synthetic scene.

#include <string>

namespace sadsplat {
namespace pipeline {

/// \brief Scores the run's Gaussians against the true surfaces of its scene's world (a scene made
/// by `sadsplat synth`, whose source names the world): point mIoU / OA (plain and opacity
/// weighted), distance of opaque centres to the nearest true surface, and completeness of the
/// true top surface per class; on `scene_override` when given (a copied run whose scene moved).
/// Writes RUN/metrics_3d.json and returns its text.
/// \throws sadsplat::Error when the run has no classes or its scene names no generated world
std::string evalCloudRun(const std::string& run_dir, const std::string& scene_override = "");

}  // namespace pipeline
}  // namespace sadsplat
