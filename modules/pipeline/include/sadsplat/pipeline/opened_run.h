#pragma once
/// \file opened_run.h
/// \brief A scene loaded for a job, and a trained run opened for rendering and evaluation
/// (`sadsplat eval`, `ortho`, `render`, `view`): its files are io::RunDirectory's.

#include <memory>
#include <ostream>
#include <string>

#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pipeline {

/// \brief What loadScene does with a scene cache's pixels.
enum class ScenePixels {
  kRead,        ///< read them all into host memory
  kLeftOnDisk,  ///< leave them in the file (io::readSceneCacheWithoutPixels): the training reads
                ///< each view from it (trainRun and BlockRun always do); a scene directory is
                ///< imported whole anyway
};

/// \brief Loads a scene directory (imported at `scale`, needs OpenCV; said on `progress` when
/// not null) or a scene cache file.
io::Scene loadScene(const std::string& path, double scale = 0.5, std::ostream* progress = nullptr,
                    ScenePixels pixels = ScenePixels::kRead);

/// \brief A trained run opened for rendering: its scene, configuration and model (the trainer
/// restored from checkpoint.bin).
struct OpenedRun {
  std::string dir;
  std::string scene_path;  ///< the scene the run trained on (or the override)
  double scale = 0.5;      ///< the import scale of a scene directory
  double train_seconds = 0;
  io::Scene scene;
  gaussians::TrainConfig config;
  std::unique_ptr<gaussians::Trainer> trainer;
};

/// \brief Opens a run directory (run.json, config.json, checkpoint.bin) on its scene or on
/// `scene_override`. `pixels`: what happens to a scene cache's pixels (loadScene); by default
/// they stay in the file (the commands that open a run render the model, and evaluation reads
/// each test view when it scores it), so a survey's photos are never all in host memory.
/// `views`: the trainer holds only the cameras (it renders; step() is an error), or
/// (kLoaded) reads its training views to train on.
/// \throws sadsplat::Error naming the run's file and field
OpenedRun openRun(const std::string& run_dir, const std::string& scene_override = "",
                  double scale = 0.5, ScenePixels pixels = ScenePixels::kLeftOnDisk,
                  gaussians::TrainerViews views = gaussians::TrainerViews::kCamerasOnly);

/// \brief The scene directory a run's scene was imported from (its images/ hold the photos at
/// their imported-from size), or "" when there is none: the run's scene itself, or a cache's
/// recorded source (a relative source is looked for from the folders above the cache).
std::string sceneDirectoryOf(const OpenedRun& run);

/// \brief Evaluates a run directory on its scene (or `scene_override`): writes metrics.json and
/// panels/, returns the metrics.json text.
std::string evalRun(const std::string& run_dir, const std::string& scene_override = "",
                    double scale = 0.5);

}  // namespace pipeline
}  // namespace sadsplat
