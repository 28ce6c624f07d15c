#pragma once
/// \file runs.h
/// \brief The jobs behind `sadsplat train`, `sadsplat eval` and `sadsplat demo`.
///
/// A run directory holds: config.json (the exact configuration), run.json (scene path, device,
/// iterations done, training seconds), checkpoint.bin (latest training state, written every
/// checkpoint_interval iterations and at the end), model.ply (3DGS PLY with semantic
/// properties), model.pcd (the same Gaussians as PCD), model_semantic.pcd and model_semantic.ply
/// (the plain semantic cloud: centre, class colour, class id), classes.json, and after evaluation
/// metrics.json and panels/*.png.

#include <functional>
#include <ostream>
#include <string>

#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pipeline {

/// \brief Loads a scene directory (imported at `scale`, needs OpenCV) or a scene cache file.
io::Scene loadScene(const std::string& path, double scale = 0.5);

/// \brief Options of a training run.
struct TrainRunOptions {
  std::string scene;    ///< scene directory or cache
  std::string out;      ///< run directory (created)
  double scale = 0.5;   ///< import scale for scene directories (paper: half resolution)
  bool resume = false;  ///< continue from out/checkpoint.bin
  std::ostream* progress = nullptr;  ///< live progress line (carriage returns), or none
};

/// \brief Trains and writes the run directory. Returns the training time in seconds.
/// \throws sadsplat::Error on bad input
double trainRun(const TrainRunOptions& options, const gaussians::TrainConfig& config);

/// \brief Evaluates a run directory on its scene (or `scene_override`): writes metrics.json and
/// panels/, returns the metrics.json text.
std::string evalRun(const std::string& run_dir, const std::string& scene_override = "",
                    double scale = 0.5);

/// \brief `sadsplat demo`: generates the small city scene, writes its pseudo-labels (built-in
/// backend, report in OUT/pseudo_labels), trains on CPU with the full semantic-aware drop,
/// evaluates, prints a table to `out`. `baseline` skips pseudo-labels and drop (the paper's
/// Net-1). Returns 0 on success.
int runDemo(const std::string& out_dir, int iterations, std::ostream& out, bool baseline = false);

}  // namespace pipeline
}  // namespace sadsplat
