// `sadsplat eval --ortho`: the class map, the DSM and the building objects against a map-grid
// truth.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "map_layers.h"
#include "sadsplat/common/error.h"
#include "sadsplat/common/order_statistics.h"
#include "sadsplat/eval/dsm_scores.h"
#include "sadsplat/eval/metrics.h"
#include "sadsplat/eval/object_scores.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/map_products.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/ortho_render.h"
#include "sadsplat/synth/aerial_benchmark.h"
#include "truth_world.h"

namespace sadsplat {
namespace pipeline {
namespace {

// Errors of object heights (predicted - true): how many, median and median absolute, RMSE.
nlohmann::json heightErrorsJson(std::vector<double> e) {
  nlohmann::json j = {{"objects", e.size()}};
  if (e.empty()) return j;
  double sq = 0;
  for (double v : e) sq += v * v;
  std::vector<double> a(e.size());
  std::transform(e.begin(), e.end(), a.begin(), [](double v) { return std::abs(v); });
  j["rmse"] = std::sqrt(sq / e.size());
  j["median_error"] = medianInPlace(e);  // the mean of the middle two, as eval::scoreDsm's
  j["median_abs_error"] = medianInPlace(a);
  return j;
}

}  // namespace

std::string evalOrthoRun(const std::string& run_dir, const std::string& truth_json_in,
                         const OrthoRunOptions& render, const std::string& scene_override) {
  OrthoRenderOptions render_options = checkedRenderOptions(render, "<eval>");
  OpenedRun run = openRun(run_dir, scene_override);
  if (run.trainer->numClasses() == 0) {
    throw Error(run_dir, "model", "a semantic model (classes) to score on the map", "no classes");
  }
  std::string truth_json = truth_json_in;
  if (truth_json.empty()) {
    const std::string dir = sceneDirectoryOf(run);
    truth_json = (dir.empty() ? run.scene_path : dir) + "/ortho_truth.json";
  }
  // The truth: the JSON + PNG `sadsplat synth --out` writes, or (a synth scene cache, which
  // names its world) traced again from the world.
  OrthoGrid grid;
  grid.frame = geo::localMapFrame({0, 0, 1});  // the truth is on the scene frame's x-y plane
  std::vector<std::uint8_t> truth;
  std::string truth_source = truth_json;
  const std::optional<synth::World> world = truth_json_in.empty() && !io::isRegularFile(truth_json)
                                                ? synth::worldFromId(run.scene.source)
                                                : std::nullopt;
  if (world) {
    synth::OrthoTruth t = synth::orthoTruth(*world);
    grid.gsd = t.gsd, grid.x0 = t.x0, grid.y0 = t.y0, grid.width = t.width, grid.height = t.height;
    truth = std::move(t.classes);
    truth_source = run.scene.source + " (traced)";
  } else {
    if (!io::isRegularFile(truth_json)) {
      throw Error(truth_json, "file",
                  "the map-grid ground truth (ortho_truth.json, written by `sadsplat synth`)",
                  "missing");
    }
    nlohmann::json t;
    try {
      t = nlohmann::json::parse(io::readWholeFile(truth_json));
    } catch (const nlohmann::json::exception& e) {
      throw Error(truth_json, "JSON", "valid JSON", e.what());
    }
    for (const char* key : {"gsd", "x0", "y0", "width", "height", "classes_png"}) {
      if (!t.contains(key)) throw Error(truth_json, key, "a value", "missing");
    }
    const std::size_t slash = truth_json.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : truth_json.substr(0, slash);
    const geo::Raster png = geo::readByteRaster(dir + "/" + t["classes_png"].get<std::string>());
    grid.gsd = t["gsd"].get<double>();
    grid.x0 = t["x0"].get<double>();
    grid.y0 = t["y0"].get<double>();
    grid.width = t["width"].get<int>();
    grid.height = t["height"].get<int>();
    if (png.width != grid.width || png.height != grid.height) {
      throw Error(truth_json, "width/height", "the size of " + t["classes_png"].get<std::string>(),
                  std::to_string(grid.width) + "x" + std::to_string(grid.height));
    }
    truth = png.bytes;
  }
  // The true DSM (the height of that topmost surface) where the world is known: traced on the
  // same grid (a synth cache names its world; a synth directory's ortho_truth.json does).
  std::vector<float> true_heights;
  const std::optional<synth::World> dsm_world =
      world ? world : synth::worldFromId(worldIdInTruthFile(truth_json));
  if (dsm_world) {
    synth::OrthoTruth t = synth::orthoTruth(*dsm_world, grid.gsd);
    if (t.width == grid.width && t.height == grid.height && t.x0 == grid.x0 && t.y0 == grid.y0) {
      true_heights = std::move(t.heights);
    }
  }
  grid.top = orthoTop(*run.trainer, grid.frame);
  render_options.cameras = trainingCameras(run.scene);
  pcl::PointCloud<GaussianPoint> cloud =
      setGaussianClasses(render_options, render, *run.trainer, run.scene, "<eval>");
  const OrthoImages img = renderOrtho(*run.trainer, grid, render_options);
  const int C = run.trainer->numClasses();
  eval::ConfusionMatrix confusion(C);
  std::vector<std::uint8_t> gt;
  std::vector<std::int64_t> pred;
  std::int64_t labelled = 0, uncovered = 0;
  std::vector<std::int64_t> truth_cells(C, 0), truth_covered(C, 0), predicted_cells(C, 0);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::uint8_t g = truth[i];
    if (g >= C) continue;
    ++labelled;
    ++truth_cells[g];
    if (!img.covered[i]) {
      ++uncovered;
      continue;
    }
    ++predicted_cells[img.classes[i]];
    ++truth_covered[g];
    gt.push_back(g);
    pred.push_back(img.classes[i]);
  }
  confusion.add(gt.data(), pred.data(), gt.size());
  const auto iou = confusion.perClassIou();
  // The same score over the cells near the grid's centre (what an orbit looks at): within these
  // shares of the half of the grid's shorter side.
  nlohmann::json within = nlohmann::json::array();
  const double half = 0.5 * grid.gsd * std::min(grid.width, grid.height);
  for (const double share : {0.5, 0.7, 0.9}) {
    const double r = share * half;
    const eval::ConfusionMatrix near = eval::confusionWithin(
        truth, img.classes, img.covered, grid.width, grid.height, grid.gsd, r, C);
    within.push_back({{"radius_share", share}, {"radius_m", r}, {"miou", near.meanIou()}});
  }
  nlohmann::json j;
  j["truth"] = truth_source;
  j["gsd"] = grid.gsd;
  j["cells"] = labelled;
  addRenderOptions(j, render, img, run.scene.classes);
  j["uncovered_share"] = labelled ? double(uncovered) / labelled : 0.0;
  j["miou"] = confusion.meanIou();
  j["oacc"] = confusion.overallAccuracy();
  j["miou_within"] = within;
  nlohmann::json per_class = nlohmann::json::object(), area = nlohmann::json::object();
  const double cell_area = grid.gsd * grid.gsd;
  for (int c = 0; c < C; ++c) {
    const std::string& name = run.scene.classes[c].name;
    per_class[name] = iou[c] < 0 ? nlohmann::json(nullptr) : nlohmann::json(iou[c]);
    nlohmann::json a;
    // The error where the map says something (its nodata cells are neither class), and
    // against the whole labelled area (nodata counting as missing).
    a["truth_m2"] = truth_cells[c] * cell_area;
    a["truth_covered_m2"] = truth_covered[c] * cell_area;
    a["predicted_m2"] = predicted_cells[c] * cell_area;
    a["relative_error"] = nullptr;
    a["relative_error_all"] = nullptr;
    if (truth_covered[c] > 0) {
      a["relative_error"] = double(predicted_cells[c] - truth_covered[c]) / truth_covered[c];
    }
    if (truth_cells[c] > 0) {
      a["relative_error_all"] = double(predicted_cells[c] - truth_cells[c]) / truth_cells[c];
    }
    area[name] = a;
  }
  j["per_class_iou"] = per_class;
  j["area"] = area;
  // Where each true class went, in cells: rows the true class, columns the mapped class (the
  // scene's class order, as `classes`), and per true class its cells the map leaves nodata.
  nlohmann::json matrix = nlohmann::json::array(), nodata = nlohmann::json::array(),
                 names = nlohmann::json::array();
  for (int t = 0; t < C; ++t) {
    names.push_back(run.scene.classes[t].name);
    nlohmann::json row = nlohmann::json::array();
    for (int p = 0; p < C; ++p) row.push_back(confusion.at(t, p));
    matrix.push_back(row);
    nodata.push_back(truth_cells[t] - truth_covered[t]);
  }
  j["confusion"] = {{"classes", names}, {"cells", matrix}, {"nodata_cells", nodata}};
  // DSM error (the rendered elevation against the true top surface's height) over covered cells
  // of the labelled area, all and per true class: roofs, ground, vegetation apart; also away
  // from the truth's height steps (walls), where a fraction of a cell costs metres.
  if (!true_heights.empty()) {
    eval::DsmScoreOptions dsm_options;
    const eval::DsmScores scores = eval::scoreDsm(img.elevation, true_heights, truth, img.covered,
                                                  grid.width, grid.height, C, dsm_options);
    const auto summary = [](const eval::HeightErrors& e) {
      nlohmann::json d;
      d["cells"] = e.cells;
      if (e.cells == 0) return d;
      d["rmse_m"] = e.rmse_m;
      d["median_abs_m"] = e.median_abs_m;
      d["nmad_m"] = e.nmad_m;
      d["off_step_cells"] = e.off_step_cells;
      d["off_step_rmse_m"] = e.off_step_cells ? nlohmann::json(e.off_step_rmse_m) : nullptr;
      return d;
    };
    nlohmann::json dsm = summary(scores.all);
    dsm["step_m"] = dsm_options.step_m;
    nlohmann::json dsm_class = nlohmann::json::object();
    for (int c = 0; c < C; ++c) dsm_class[run.scene.classes[c].name] = summary(scores.per_class[c]);
    dsm["per_class"] = dsm_class;
    j["dsm"] = dsm;
  }
  // Buildings as map objects: the building cells split where the DSM steps by more than
  // render.object_step (as `ortho --vectors` writes them; slivers under kMinObjectM2 merged, and
  // objects under it not counted) against the world's standing buildings rasterised on the
  // grid, matched at IoU >= 0.5; also for other steps (0: the plain 8-connected regions).
  int building = -1;
  for (int c = 0; c < C; ++c) building = run.scene.classes[c].name == "building" ? c : building;
  if (dsm_world && !true_heights.empty() && building >= 0) {
    const std::size_t n_cells = static_cast<std::size_t>(grid.width) * grid.height;
    std::vector<int> truth_objects(n_cells, 0);
    const auto footprints =
        synth::groundFootprints(*dsm_world, static_cast<std::uint8_t>(building));
    for (std::size_t f = 0; f < footprints.size(); ++f) {
      const synth::ObjectFootprint& b = footprints[f];
      const int i0 = std::max(0, static_cast<int>(std::ceil((b.x0 - grid.x0) / grid.gsd - 0.5)));
      const int i1 =
          std::min(grid.width - 1, static_cast<int>(std::floor((b.x1 - grid.x0) / grid.gsd - 0.5)));
      const int j0 = std::max(0, static_cast<int>(std::ceil((grid.y0 - b.y1) / grid.gsd - 0.5)));
      const int j1 = std::min(grid.height - 1,
                              static_cast<int>(std::floor((grid.y0 - b.y0) / grid.gsd - 0.5)));
      for (int jj = j0; jj <= j1; ++jj) {
        for (int ii = i0; ii <= i1; ++ii) {
          truth_objects[static_cast<std::size_t>(jj) * grid.width + ii] = static_cast<int>(f) + 1;
        }
      }
    }
    const std::size_t min_cells = minObjectCells(grid.gsd);
    // The cloud's building objects as `ortho --object-clouds` hands them out: the Gaussians
    // under each map object, their footprint the convex hull of their centres (as `eval --3d`
    // scores the clustered cloud's), against the true footprints.
    if (cloud.empty()) cloud = labelledCloud(*run.trainer, run.scene);
    std::vector<std::array<float, 3>> centres(cloud.size());
    for (std::size_t g = 0; g < cloud.size(); ++g)
      centres[g] = {cloud[g].x, cloud[g].y, cloud[g].z};
    std::vector<eval::Footprint> true_footprints;
    for (const synth::ObjectFootprint& b : footprints) {
      true_footprints.push_back({{b.x0, b.y0}, {b.x1, b.y0}, {b.x1, b.y1}, {b.x0, b.y1}});
    }
    const eval::ObjectScoreOptions cloud_options;  // groups under 20 Gaussians are no objects
    // The map's objects at one step (JSON) and the cloud's grouped by them.
    struct StepScores {
      nlohmann::json map;
      eval::ObjectScores cloud;
    };
    const auto objectScores = [&](double step) {
      const ClassObjects objects = classObjects(img, {building}, step, min_cells);
      const eval::ObjectScores o =
          eval::scoreRasterObjects(objects.labels, truth_objects, min_cells);
      nlohmann::json scored = buildingObjectsJson(
          o, {{"min_area_m2", kMinObjectM2}, {"object_step_m", step}, {"match_iou", 0.5}});
      // The matched objects' heights (as `ortho --vectors` writes them) against the true
      // building's top: the world's ground is z = 0, so its top is also its height above ground.
      std::vector<double> dsm_errors, above_errors;
      for (const auto& [t, p] : o.matches) {
        const synth::ObjectFootprint& f =
            footprints[static_cast<std::size_t>(o.true_labels[t]) - 1];
        const double top = dsm_world->objects()[static_cast<std::size_t>(f.object)].hi[2];
        const geo::MapObjectAttributes& a =
            objects.objects[static_cast<std::size_t>(o.predicted_labels[p]) - 1];
        dsm_errors.push_back(a.height - top);
        if (std::isfinite(a.height_above_ground))
          above_errors.push_back(a.height_above_ground - top);
      }
      scored["height_m"] = heightErrorsJson(dsm_errors);
      scored["height_above_ground_m"] = heightErrorsJson(above_errors);
      const eval::ObjectScores in_cloud = eval::scoreGroupedPoints(
          centres, objectGaussians(cloud, grid, objects, kObjectMinOpacity), true_footprints,
          cloud_options);
      scored["cloud_f1"] = in_cloud.f1;
      return StepScores{scored, in_cloud};
    };
    nlohmann::json by_step = nlohmann::json::array();
    std::optional<StepScores> at_step;  // render.object_step's
    for (const double step : {0.0, 3.0, 2.0, 1.5, 1.0, 0.5}) {
      StepScores scores = objectScores(step);
      by_step.push_back(scores.map);
      if (step == render.object_step) at_step = std::move(scores);
    }
    if (!at_step) at_step = objectScores(render.object_step);
    j["objects"] = at_step->map;
    j["cloud_objects"] = buildingObjectsJson(
        at_step->cloud, {{"object_step_m", render.object_step},
                         {"min_opacity", kObjectMinOpacity},
                         {"min_points", cloud_options.min_points},
                         {"match_iou", cloud_options.match_iou},
                         {"footprint", "the convex hull of the Gaussians' centres"}});
    j["objects_by_step"] = by_step;
  }
  const std::string text = j.dump(2) + "\n";
  io::writeTextFileAtomically(run_dir + "/ortho_metrics.json", text);
  return text;
}

}  // namespace pipeline
}  // namespace sadsplat
