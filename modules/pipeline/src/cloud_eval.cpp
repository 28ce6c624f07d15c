#include "sadsplat/pipeline/cloud_eval.h"

#include <nlohmann/json.hpp>

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/eval/cloud_scores.h"
#include "sadsplat/eval/object_scores.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/raised_gaussians.h"
#include "sadsplat/synth/aerial_benchmark.h"
#include "truth_world.h"

namespace sadsplat {
namespace pipeline {
namespace {

// The true top surface, sampled on a map grid of this spacing (metres).
constexpr double kSurfaceSpacing = 0.5;

nlohmann::json perClass(const std::vector<ClassInfo>& classes, const std::vector<double>& values) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t c = 0; c < classes.size() && c < values.size(); ++c) {
    j[classes[c].name] = values[c] < 0 ? nlohmann::json(nullptr) : nlohmann::json(values[c]);
  }
  return j;
}

std::vector<eval::CloudPoint> cloudPoints(const pcl::PointCloud<GaussianPoint>& cloud,
                                          int classes) {
  std::vector<eval::CloudPoint> points(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    points[i].xyz = {cloud[i].x, cloud[i].y, cloud[i].z};
    points[i].cls = cloud[i].label < static_cast<std::uint32_t>(classes)
                        ? static_cast<int>(cloud[i].label)
                        : -1;
    points[i].opacity = 1.f / (1.f + std::exp(-cloud[i].opacity));
  }
  return points;
}

// What every part of the cloud scored apart (over the map's area, on the surface) reports.
nlohmann::json partScores(std::size_t gaussians, const eval::CloudScores& k) {
  return {{"gaussians", gaussians},
          {"point_miou", k.miou},
          {"opaque", k.opaque},
          {"share_within_0.5_m", k.share_near},
          {"share_beyond_1.0_m", k.share_far},
          {"distance_p90_m", k.p90_metres}};
}

}  // namespace

std::string evalCloudRun(const std::string& run_dir, const std::string& scene_override) {
  OpenedRun run = openRun(run_dir, scene_override);
  const int C = run.trainer->numClasses();
  if (C == 0) {
    throw Error(run_dir, "model", "a semantic model (classes) to score in 3D", "no classes");
  }
  // The world: named by a synth scene cache's source, or by a synth scene directory's
  // ortho_truth.json.
  std::string world_id = run.scene.source;
  std::optional<synth::World> world = synth::worldFromId(world_id);
  const std::string dir = sceneDirectoryOf(run);
  if (!world && !dir.empty()) {
    world_id = worldIdInTruthFile(dir + "/ortho_truth.json");
    world = synth::worldFromId(world_id);
  }
  if (!world) {
    throw Error(run.scene_path, "source",
                "a scene made by `sadsplat synth` (its world is the 3D truth)",
                "\"" + run.scene.source.substr(0, 80) + "\"");
  }
  // The cloud as PCL users take it (model_semantic): each Gaussian's class from the views; for
  // comparison also the class of its own decoded feature.
  const auto cloud = labelledCloud(*run.trainer, run.scene);
  const std::vector<eval::CloudPoint> points = cloudPoints(cloud, C);
  // The same cloud with the raised-class check: a raised class's Gaussians at ground height
  // belong to no class (what `extract --raised-check` leaves out).
  const RaisedGaussianOptions raised_options;
  const geo::LowRaisedCells low = findLowRaisedGaussians(cloud, run.scene, C, raised_options);
  std::vector<eval::CloudPoint> checked_points = points;
  for (const std::size_t i : low.cells) checked_points[i].cls = -1;
  const std::vector<eval::CloudPoint> feature_points = cloudPoints(run.trainer->toCloud(), C);
  const eval::NearestTruthSurface truth = [&](const std::array<float, 3>& p) {
    const synth::NearestSurface s = world->nearestSurface(p.data());
    return eval::TruthSurface{s.distance, s.cls};
  };
  const synth::OrthoTruth top = synth::orthoTruth(*world, kSurfaceSpacing);
  std::vector<eval::SurfaceSample> surface;
  for (int j = 0; j < top.height; ++j) {
    for (int i = 0; i < top.width; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * top.width + i;
      if (top.classes[k] >= C || !std::isfinite(top.heights[k])) continue;
      surface.push_back({{static_cast<float>(top.x0 + (i + 0.5) * top.gsd),
                          static_cast<float>(top.y0 - (j + 0.5) * top.gsd), top.heights[k]},
                         top.classes[k]});
    }
  }
  eval::CloudScoreOptions options;
  options.num_classes = C;
  const eval::CloudScores s = eval::scoreCloud(points, truth, surface, options);

  nlohmann::json j;
  j["truth"] = world_id + " (nearest true surface; top surface every " +
               std::to_string(kSurfaceSpacing).substr(0, 3) + " m)";
  j["gaussians"] = cloud.size();
  j["scored"] = s.points;
  j["point_miou"] = s.miou;
  j["point_oacc"] = s.oacc;
  j["point_iou"] = perClass(run.scene.classes, s.iou);
  j["weighted_miou"] = s.weighted_miou;
  j["weighted_oacc"] = s.weighted_oacc;
  j["weighted_iou"] = perClass(run.scene.classes, s.weighted_iou);
  j["labels"] = "the class the training views render where the Gaussian draws (labelled_cloud.h)";
  const eval::CloudScores f = eval::scoreCloud(feature_points, truth, surface, options);
  j["feature_labels"] = {{"point_miou", f.miou},
                         {"point_oacc", f.oacc},
                         {"weighted_miou", f.weighted_miou},
                         {"point_iou", perClass(run.scene.classes, f.iou)}};
  j["opaque_at"] = options.opaque;
  j["opaque"] = s.opaque;
  j["distance_median_m"] = s.median_metres;
  j["distance_p90_m"] = s.p90_metres;
  j["distance_median_all_m"] = s.median_all_metres;
  j["distance_p90_all_m"] = s.p90_all_metres;
  j["share_within_" + std::to_string(options.near_metres).substr(0, 3) + "_m"] = s.share_near;
  j["share_beyond_" + std::to_string(options.far_metres).substr(0, 3) + "_m"] = s.share_far;
  j["distance_median_per_class_m"] = perClass(run.scene.classes, s.median_per_class);
  j["share_beyond_1.0_m_per_class"] = perClass(run.scene.classes, s.share_far_per_class);
  nlohmann::json confusion = nlohmann::json::array();
  for (int t = 0; t < C; ++t) {
    nlohmann::json row = nlohmann::json::array();
    for (int p = 0; p < C; ++p) row.push_back(s.confusion[static_cast<std::size_t>(t) * C + p]);
    confusion.push_back(row);
  }
  j["confusion"] = confusion;  // rows: the nearest true surface's class; columns: the Gaussian's
  // The same distances over the map's area only (the labelled world's square, as `eval --ortho`
  // scores it): the far terrain oblique photos see beyond it left out.
  const double x1 = top.x0 + top.width * top.gsd, y0 = top.y0 - top.height * top.gsd;
  const std::vector<eval::CloudPoint> over_map = eval::pointsOver(points, top.x0, y0, x1, top.y0);
  // No surface samples: its completeness is not reported.
  const eval::CloudScores over = eval::scoreCloud(over_map, truth, {}, options);
  j["over_map"] = partScores(over_map.size(), over);
  j["over_map"]["bounds"] = {top.x0, y0, x1, top.y0};
  j["over_map"]["distance_median_m"] = over.median_metres;
  // Objects: the buildings as examples/building_footprints extracts them (opaque Gaussians of
  // the class, Euclidean clusters), against the world's standing buildings.
  int building = -1;
  for (int c = 0; c < C; ++c) {
    if (run.scene.classes[c].name == "building") building = c;
  }
  std::vector<eval::Footprint> truth_footprints;
  if (building >= 0) {
    for (const synth::ObjectFootprint& f :
         synth::groundFootprints(*world, static_cast<std::uint8_t>(building))) {
      truth_footprints.push_back({{f.x0, f.y0}, {f.x1, f.y0}, {f.x1, f.y1}, {f.x0, f.y1}});
    }
  }
  // The example's extraction: the class's opaque centres, clustered at its automatic tolerance
  // (eval::autoClusterTolerance of their spacing).
  const auto centresOf = [&](const std::vector<eval::CloudPoint>& cloud_points) {
    std::vector<std::array<float, 3>> centres;
    for (const eval::CloudPoint& p : cloud_points) {
      if (p.cls == building && p.opacity >= options.opaque) centres.push_back(p.xyz);
    }
    return centres;
  };
  const double spacing = eval::medianNeighbourDistance(centresOf(points));
  eval::ObjectScoreOptions object_options;
  object_options.tolerance = eval::autoClusterTolerance(spacing);
  const auto buildingObjects = [&](const std::vector<eval::CloudPoint>& cloud_points,
                                   const eval::ObjectScoreOptions& o) {
    return eval::scoreObjects(centresOf(cloud_points), truth_footprints, o);
  };
  // The cloud `extract --on-surface M` hands out: the Gaussians at most M from the surface the
  // views render where they draw.
  const std::vector<float> gaps = surfaceGaps(*run.trainer, run.scene);
  nlohmann::json on_surface = nlohmann::json::array();
  for (const float limit : {0.5f, 1.0f, 2.0f}) {
    std::vector<eval::CloudPoint> kept, kept_checked;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (gaps[i] <= limit) kept.push_back(points[i]), kept_checked.push_back(checked_points[i]);
    }
    const eval::CloudScores k = eval::scoreCloud(kept, truth, surface, options);
    on_surface.push_back(partScores(kept.size(), k));
    on_surface.back()["max_gap_m"] = limit;
    on_surface.back()["completeness_all"] = k.completeness_all;
    if (building >= 0) {
      on_surface.back()["objects_f1"] = buildingObjects(kept, object_options).f1;
      on_surface.back()["objects_f1_raised_check"] =
          buildingObjects(kept_checked, object_options).f1;
    }
  }
  j["on_surface"] = on_surface;
  j["completeness_within_m"] = options.complete_metres;
  j["completeness"] = perClass(run.scene.classes, s.completeness);
  j["completeness_all"] = s.completeness_all;
  if (building >= 0) {
    const auto extraction = [&](const eval::ObjectScoreOptions& o) {
      return nlohmann::json{{"cluster_tolerance_m", o.tolerance},
                            {"min_points", o.min_points},
                            {"match_iou", o.match_iou}};
    };
    j["building_spacing_m"] = spacing;
    nlohmann::json rule = extraction(object_options);
    rule["tolerance_rule"] = "auto: 4 x the median neighbour spacing, at least 1 m, at most 3 m";
    j["objects"] = buildingObjectsJson(buildingObjects(points, object_options), rule);
    eval::ObjectScoreOptions fixed;  // 1 m: the example's tolerance before the automatic one
    j["objects_tolerance_1m"] =
        buildingObjectsJson(buildingObjects(points, fixed), extraction(fixed));
    nlohmann::json checked = extraction(object_options);
    checked.update({{"raised_check", raised_options.share},
                    {"gaussians_unclassed", low.cells.size()},
                    {"near_ground_share", low.near_ground}});
    j["objects_raised_check"] =
        buildingObjectsJson(buildingObjects(checked_points, object_options), checked);
    // Other tolerances, with and without the raised-class check.
    const auto scoredAt = [&](double tolerance, const nlohmann::json& extra) {
      eval::ObjectScoreOptions o;
      o.tolerance = tolerance;
      nlohmann::json entry = extraction(o);
      entry.update(extra);
      entry["f1_raised_check"] = buildingObjects(checked_points, o).f1;
      return buildingObjectsJson(buildingObjects(points, o), entry);
    };
    nlohmann::json by_spacing = nlohmann::json::array(), by_tolerance = nlohmann::json::array();
    for (const double k : {1.5, 2.0, 3.0, 4.0, 6.0}) {  // multiples of the spacing, >= 1 m
      by_spacing.push_back(scoredAt(std::max(1.0, k * spacing), {{"spacing_factor", k}}));
    }
    // Fixed tolerances in metres (a ceiling on the automatic rule: neighbours closer than the
    // tolerance join one object).
    for (const double metres : {1.5, 2.0, 2.5, 3.0, 4.0}) {
      by_tolerance.push_back(scoredAt(metres, nlohmann::json::object()));
    }
    j["objects_by_spacing"] = by_spacing;
    j["objects_by_tolerance"] = by_tolerance;
  }
  const std::string text = j.dump(2) + "\n";
  io::writeTextFileAtomically(run_dir + "/metrics_3d.json", text);
  return text;
}

}  // namespace pipeline
}  // namespace sadsplat
