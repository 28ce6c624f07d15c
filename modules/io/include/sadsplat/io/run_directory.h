#pragma once
/// \file run_directory.h
/// \brief The files of a training run (`sadsplat train --out RUN`), named in this one place.
///
/// A run directory holds config.json (the exact, resolved configuration), run.json (scene path,
/// import scale, device, iterations done, training seconds), checkpoint.bin (the training state,
/// written every checkpoint_interval iterations and at the end), model.ply (3DGS PLY with semantic
/// properties), model.pcd (the same Gaussians as PCD), model_semantic.pcd / model_semantic.ply
/// (the plain semantic cloud: centre, class colour, class id), classes.json, georeference.json (a
/// georeferenced scene's frame), train_log.jsonl, and after `eval` metrics.json and panels/.
/// A run trained block by block also holds blocks.json and blocks/bNNN/, each a run directory.

#include <string>

namespace sadsplat {
namespace io {

/// \brief run.json: what `sadsplat train` records beside the checkpoint.
struct RunRecord {
  std::string scene;   ///< absolute path of the scene directory or cache trained on
  double scale = 0.5;  ///< import scale of a scene directory
  std::string device = "cpu";
  int iterations = 0;  ///< iterations the checkpoint holds
  double train_seconds = 0;
};

/// \brief The paths of one run directory's files.
class RunDirectory {
 public:
  explicit RunDirectory(std::string path) : path_(std::move(path)) {}

  /// \brief Whether `path` is a run directory (run.json and model.ply in it).
  static bool isRun(const std::string& path);
  /// \brief Whether `path` is a run directory whose training can be restored (run.json and
  /// checkpoint.bin in it).
  static bool hasCheckpoint(const std::string& path);

  const std::string& path() const { return path_; }
  std::string runJson() const { return file("run.json"); }
  std::string config() const { return file("config.json"); }
  std::string checkpoint() const { return file("checkpoint.bin"); }
  std::string model() const { return file("model.ply"); }
  std::string modelPcd() const { return file("model.pcd"); }
  std::string semanticPcd() const { return file("model_semantic.pcd"); }
  std::string semanticPly() const { return file("model_semantic.ply"); }
  std::string classes() const { return file("classes.json"); }
  std::string georeference() const { return file("georeference.json"); }
  std::string trainLog() const { return file("train_log.jsonl"); }
  std::string metrics() const { return file("metrics.json"); }
  std::string panels() const { return file("panels"); }
  std::string profile() const { return file("profile.md"); }
  std::string profileOperators() const { return file("profile_operators.md"); }
  /// \brief A block run's partition (geo::BlockPartition::toJson).
  std::string blocksJson() const { return file("blocks.json"); }
  /// \brief The run directory of block `index` of a block run (blocks/b000, ...).
  RunDirectory block(int index) const;

  /// \brief Reads run.json (`scene` required unless `scene_required` is false; a missing scale,
  /// device or count keeps its default).
  /// \throws sadsplat::Error naming run.json and the field
  RunRecord readRecord(bool scene_required = true) const;
  /// \brief Writes run.json atomically (the scene path made absolute, so that `eval` finds it
  /// from any working directory).
  void writeRecord(const RunRecord& record) const;

 private:
  std::string file(const char* name) const { return path_ + "/" + name; }
  std::string path_;
};

}  // namespace io
}  // namespace sadsplat
