#pragma once
// The generating world a synth truth file names (pipeline-internal: `eval --ortho` and
// `eval --3d` both find the world of a synth scene directory through its ortho_truth.json).
#include <nlohmann/json.hpp>

#include <string>

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

}  // namespace pipeline
}  // namespace sadsplat
