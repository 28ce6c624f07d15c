#include "sadsplat/pipeline/las_frame.h"

#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/pipeline/opened_run.h"

namespace sadsplat {
namespace pipeline {

geo::LasExportOptions lasOptionsForModel(const std::string& model_path,
                                         const std::string& classification_map,
                                         std::ostream* notes) {
  geo::LasExportOptions options = geo::lasOptionsBeside(model_path, classification_map);
  if (options.georeference) return options;
  const io::RunDirectory run(geo::modelFolder(model_path));
  const auto axes = [&](const std::string& why) {
    if (notes != nullptr) {
      *notes << "sadsplat: note: " << why
             << ": the LAS keeps the scene's own axes (the maps of `ortho` use local metres with "
                "z up)\n";
    }
    return options;
  };
  if (!io::optionalFileExists(run.runJson())) return axes("no run.json beside " + model_path);
  const io::RunRecord record = run.readRecord(/*scene_required=*/false);
  if (record.scene.empty() || !io::pathExists(record.scene)) {
    return axes("the run's scene " + (record.scene.empty() ? "(none)" : record.scene) +
                " is not there to give the up direction");
  }
  if (io::isDirectory(record.scene) && !io::haveSceneImport()) {
    return axes("this build cannot import the run's scene directory " + record.scene);
  }
  const io::Scene scene = loadScene(record.scene, record.scale, nullptr, ScenePixels::kLeftOnDisk);
  options.local_frame = geo::localMapFrame(geo::sceneUp(scene));
  return options;
}

}  // namespace pipeline
}  // namespace sadsplat
