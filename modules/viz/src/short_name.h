#pragma once
// How views and reports name a run or a model file.
#include <filesystem>
#include <string>

namespace sadsplat {
namespace viz {

// The last two path components ("demo/run", "demo/model.ply"): runs and models are often all
// called "run" and "model.ply", so the last component alone does not tell two apart.
inline std::string shortName(const std::string& path) {
  std::filesystem::path normal = std::filesystem::absolute(path).lexically_normal();
  if (normal.filename().empty()) normal = normal.parent_path();
  return (normal.parent_path().filename() / normal.filename()).generic_string();
}

}  // namespace viz
}  // namespace sadsplat
