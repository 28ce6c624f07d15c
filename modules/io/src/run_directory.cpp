#include "sadsplat/io/run_directory.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {

RunDirectory RunDirectory::block(int index) const {
  std::string number = std::to_string(index);
  number.insert(0, number.size() < 3 ? 3 - number.size() : 0, '0');
  return RunDirectory(path_ + "/blocks/b" + number);
}

bool RunDirectory::isRun(const std::string& path) {
  const RunDirectory run(path);
  return isDirectory(path) && isRegularFile(run.runJson()) && isRegularFile(run.model());
}

bool RunDirectory::hasCheckpoint(const std::string& path) {
  const RunDirectory run(path);
  return isDirectory(path) && isRegularFile(run.runJson()) && isRegularFile(run.checkpoint());
}

RunRecord RunDirectory::readRecord(bool scene_required) const {
  const std::string path = runJson();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(readWholeFile(path));
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, "JSON", "the run.json that `sadsplat train` writes", e.what());
  }
  if (!j.is_object()) throw Error(path, "top level", "a JSON object", j.type_name());
  const bool has_scene = j.contains("scene") && j["scene"].is_string();
  if (scene_required && !has_scene) {
    throw Error(path, "scene", "the path of the run's scene (a string)",
                j.contains("scene") ? j["scene"].dump().substr(0, 40) : std::string("missing"));
  }
  RunRecord r;
  if (has_scene) r.scene = j["scene"].get<std::string>();
  if (j.contains("scale") && j["scale"].is_number()) r.scale = j["scale"].get<double>();
  if (j.contains("device") && j["device"].is_string()) r.device = j["device"].get<std::string>();
  if (j.contains("iterations") && j["iterations"].is_number_integer())
    r.iterations = j["iterations"].get<int>();
  if (j.contains("train_seconds") && j["train_seconds"].is_number())
    r.train_seconds = j["train_seconds"].get<double>();
  return r;
}

void RunDirectory::writeRecord(const RunRecord& r) const {
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(r.scene, error);
  const nlohmann::json j = {{"scene", error ? r.scene : absolute.lexically_normal().string()},
                            {"scale", r.scale},
                            {"device", r.device},
                            {"iterations", r.iterations},
                            {"train_seconds", r.train_seconds}};
  writeTextFileAtomically(runJson(), j.dump(2) + "\n");
}

}  // namespace io
}  // namespace sadsplat
