#pragma once
// The generating world a synth truth file names, and the scores against its buildings
// (pipeline-internal: `eval --ortho` and `eval --3d` both find the world of a synth scene
// directory through its ortho_truth.json and report buildings as objects alike).
#include <nlohmann/json.hpp>

#include <string>

#include "sadsplat/eval/object_scores.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace pipeline {

// The "world" (`synth:KIND:SEED:TILES`) of the ortho_truth.json at `path`, or "" when the file
// is absent, unreadable as JSON or names none (older files).
inline std::string worldIdInTruthFile(const std::string& path) {
  if (!io::optionalFileExists(path)) return "";
  const nlohmann::json t =
      nlohmann::json::parse(io::readWholeFile(path), nullptr, /*allow_exceptions=*/false);
  if (!t.is_object() || !t.contains("world") || !t["world"].is_string()) return "";
  return t["world"].get<std::string>();
}

// The "objects" entry of metrics_3d.json / ortho_metrics.json: how the objects were extracted
// (`extraction`, e.g. the clustering's settings) and the scores of the building objects.
inline nlohmann::json buildingObjectsJson(const eval::ObjectScores& o, nlohmann::json extraction) {
  double best_sum = 0;
  for (double v : o.best_iou) best_sum += v;
  nlohmann::json j = {{"class", "building"}};
  j.update(extraction);
  j.update({{"true", o.true_objects},
            {"predicted", o.predicted},
            {"matched", o.matched},
            {"precision", o.precision},
            {"recall", o.recall},
            {"f1", o.f1},
            {"mean_matched_iou", o.mean_matched_iou},
            {"mean_best_iou", o.true_objects ? best_sum / o.true_objects : 0.0}});
  return j;
}

}  // namespace pipeline
}  // namespace sadsplat
