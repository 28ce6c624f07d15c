// `sadsplat pick-views SCENE`: which photos to annotate (geo/annotation_views.h).
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/geo/annotation_views.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"

namespace sadsplat {
namespace cli {
namespace {

std::string percent(double share) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(1) << 100 * share << " %";
  return out.str();
}

class PickViewsCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "pick-views",
        "Which photos to annotate: the training views that together see most of the ground "
        "(by the cameras and sparse points, before any label exists)");
    c->add_option("SCENE", scene_, "scene directory (from `sfm`) or scene cache")->required();
    c->add_option("--count", options_.count, "photos to pick")->capture_default_str();
    c->add_option("--cells", options_.cells,
                  "footprint cells along the ground's longer side (finer: more exact shares)")
        ->capture_default_str();
    c->add_flag("--keep-labelled", options_.keep_labelled,
                "scene cache: take its labelled views as picked and pick --count more");
    c->add_option("--test-every", test_every_,
                  "scene directory without split.json: every Nth photo is a test view, as "
                  "`import --test-every` (not picked)")
        ->capture_default_str();
    c->add_option("--json", json_, "also write the choice as JSON");
    return c;
  }

  int run(const Invocation&) override {
    io::Scene scene;
    if (io::isSceneCache(scene_)) {
      scene = io::readSceneCacheWithoutPixels(scene_);
    } else if (io::isDirectory(scene_)) {
      io::ImportOptions import;
      import.max_width = 320;  // the cameras are scaled with the images; only geometry is used
      import.test_every = test_every_;
      scene = io::importScene(scene_, import);
    } else {
      throw Error(scene_, "SCENE", "a scene directory or scene cache", "neither");
    }
    const geo::AnnotationViews choice = geo::chooseAnnotationViews(scene, options_, scene_);
    std::cout << "footprint: " << choice.footprint_cells << " cells of " << std::setprecision(3)
              << choice.cell_size << (scene.georeference ? " m" : " scene units")
              << "; all training views together see " << percent(choice.all_share) << " of it\n";
    if (!choice.kept.empty()) {
      std::cout << choice.kept.size() << " labelled view(s) kept, seeing "
                << percent(choice.kept_share) << "\n";
    }
    std::cout << "annotate these " << choice.picked.size()
              << " photo(s) (each sees the most ground the ones before do not):\n";
    for (std::size_t k = 0; k < choice.picked.size(); ++k) {
      std::cout << "  " << scene.views[choice.picked[k]].name << "  sees "
                << percent(choice.own_share[k]) << " alone, " << percent(choice.cumulative_share[k])
                << " with those before\n";
    }
    std::cout << "then: rough polygons of every class in them (LabelMe or COCO) and `sadsplat "
                 "import SCENE --annotations FILE_OR_FOLDER --out S.cache`\n";
    if (!json_.empty()) writeJson(scene, choice);
    return 0;
  }

 private:
  void writeJson(const io::Scene& scene, const geo::AnnotationViews& choice) const {
    nlohmann::json j;
    j["scene"] = scene_;
    j["count"] = options_.count;
    j["cells"] = options_.cells;
    j["footprint_cells"] = choice.footprint_cells;
    j["cell_size"] = choice.cell_size;
    j["all_share"] = choice.all_share;
    j["kept"] = nlohmann::json::array();
    for (int v : choice.kept) j["kept"].push_back(scene.views[v].name);
    j["kept_share"] = choice.kept_share;
    j["picked"] = nlohmann::json::array();
    for (std::size_t k = 0; k < choice.picked.size(); ++k) {
      j["picked"].push_back({{"name", scene.views[choice.picked[k]].name},
                             {"own_share", choice.own_share[k]},
                             {"cumulative_share", choice.cumulative_share[k]}});
    }
    io::writeTextFileAtomically(json_, j.dump(2) + "\n");
  }

  std::string scene_, json_;
  geo::AnnotationViewOptions options_;
  int test_every_ = 8;
};

}  // namespace

std::unique_ptr<Command> makePickViewsCommand() { return std::make_unique<PickViewsCommand>(); }

}  // namespace cli
}  // namespace sadsplat
