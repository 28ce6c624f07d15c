#include "sadsplat/pipeline/opened_run.h"

#include <ATen/Context.h>

#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/eval/evaluation.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/semantic_drop/drop_strategy.h"

namespace sadsplat {
namespace pipeline {

io::Scene loadScene(const std::string& path, double scale, std::ostream* progress,
                    ScenePixels pixels) {
  if (io::isDirectory(path)) {
    io::ImportOptions options;
    options.scale = scale;
    if (progress != nullptr) {
      *progress << "importing " << path << " at image scale " << scale
                << " (--scale; `sadsplat import` writes a scene cache to skip this step)\n";
    }
    return io::importScene(path, options);
  }
  if (pixels == ScenePixels::kLeftOnDisk) {
    if (progress != nullptr)
      *progress << "views read from " << path << " one at a time as the training needs them\n";
    return io::readSceneCacheWithoutPixels(path);
  }
  return io::readSceneCache(path);
}

OpenedRun openRun(const std::string& run_dir, const std::string& scene_override, double scale,
                  ScenePixels pixels, gaussians::TrainerViews views) {
  const io::RunDirectory dir(run_dir);
  const io::RunRecord record = dir.readRecord(/*scene_required=*/scene_override.empty());
  OpenedRun o;
  o.dir = run_dir;
  o.scene_path = scene_override.empty() ? record.scene : scene_override;
  o.scale = scene_override.empty() ? record.scale : scale;
  o.train_seconds = record.train_seconds;
  o.config = gaussians::TrainConfig::fromJson(io::readWholeFile(dir.config()), dir.config());
  // A run trained on a GPU opens on a machine without one (eval, maps, the viewer on a laptop):
  // the model then renders with the CPU rasterizer, the reference the CUDA one is tested against.
  if (o.config.device == gaussians::TrainDevice::kCuda && !at::hasCUDA()) {
    o.config.device = gaussians::TrainDevice::kCpu;
  }
  o.scene = loadScene(o.scene_path, o.scale, nullptr, pixels);
  o.trainer = std::make_unique<gaussians::Trainer>(o.scene, o.config, views);
  o.trainer->setDropStrategy(semantic_drop::makeDropStrategy(o.config));
  o.trainer->loadCheckpoint(dir.checkpoint());
  return o;
}

std::string sceneDirectoryOf(const OpenedRun& run) {
  if (io::isDirectory(run.scene_path)) return run.scene_path;
  const std::string& source = run.scene.source;
  if (source.empty()) return "";
  if (io::isDirectory(source)) return source;
  // A relative path is the one `import` was given, from the directory it ran in: usually an
  // ancestor of the cache's folder.
  if (source[0] != '/') {
    std::filesystem::path dir = std::filesystem::absolute(run.scene_path).parent_path();
    for (; !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      if (io::isDirectory((dir / source).string())) return (dir / source).string();
    }
  }
  return "";
}

std::string evalRun(const std::string& run_dir, const std::string& scene_override, double scale) {
  // The test views are read from a scene cache one at a time; the trainer holds only cameras.
  const OpenedRun run = openRun(run_dir, scene_override, scale);
  const io::RunDirectory dir(run_dir);
  io::makeDirectory(dir.panels());
  const eval::EvalResult result = eval::evaluate(*run.trainer, run.scene, dir.panels());
  eval::RunFacts facts;
  facts.num_gaussians = run.trainer->numGaussians();
  facts.iterations = run.trainer->iteration();
  facts.train_seconds = run.train_seconds;
  facts.device = gaussians::choiceName(run.config.device);
  const std::string text = eval::metricsJson(result, run.scene.classes, facts);
  io::writeTextFileAtomically(dir.metrics(), text);
  return text;
}

}  // namespace pipeline
}  // namespace sadsplat
