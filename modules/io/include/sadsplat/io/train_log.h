#pragma once
/// \file train_log.h
/// \brief RUN/train_log.jsonl: the history of a training run, one JSON object per line, for
/// plots and reports (`sadsplat report`).
///
/// Records (every field a number except `type`):
/// - `{"type":"step","iteration","loss","rgb_loss","semantic_loss","gaussians","seconds"}`:
///   every few iterations and at the last one;
/// - `{"type":"drop","iteration","removed","gaussians","low_confidence","unseen","closed_gate"}`:
///   one semantic-aware drop, with the counts of why Gaussians went;
/// - `{"type":"closed_gates","iteration","removed","gaussians"}`: the removal of closed gates
///   after the last iteration;
/// - `{"type":"recovery","iteration","removed","gaussians","closed_gate"}`: the start of the
///   recovery phase (gates folded into the opacities): `closed_gate` Gaussians with a closed gate
///   and `removed - closed_gate` least contributing ones removed;
/// - `{"type":"max_gaussians_reached","iteration","gaussians"}`: the model reached the
///   `max_gaussians` cap (densification adds no more), once per run.
/// A resumed run first drops the records after the checkpoint's iteration (those steps are
/// trained again), then appends: the log reads as one uninterrupted run.

#include <fstream>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief What to do about a `max_gaussians_reached` record: the training's progress line and
/// `sadsplat report` both say it.
inline constexpr const char* kMaxGaussiansAdvice =
    "A model that grows to the cap has not converged: raise densify_grad_threshold or lower "
    "densify_until in --config, or train with a drop";

/// \brief One record of a train log.
struct TrainLogRecord {
  std::string type = "step";  ///< step, drop, closed_gates, recovery, max_gaussians_reached
  int iteration = 0;
  double loss = 0, rgb_loss = 0, semantic_loss = 0;  ///< step records
  double seconds = 0;                                ///< training time so far (step records)
  long long gaussians = 0;                           ///< Gaussians after the event
  long long removed = 0;                             ///< drop / closed_gates records
  long long low_confidence = 0, unseen = 0, closed_gate = 0;  ///< drop (recovery): why they went
};

/// \brief Appends records to a JSON-lines train log, one flushed line each.
class TrainLogWriter {
 public:
  /// \param[in] path the log file: created, or for a resumed run (`resume_iteration` >= 0) cut
  /// to the records of iterations up to `resume_iteration`
  /// \throws sadsplat::Error naming the file when it cannot be read or written
  TrainLogWriter(const std::string& path, int resume_iteration);
  /// \brief Appends one record.
  /// \throws sadsplat::Error naming the file when the write fails
  void append(const TrainLogRecord& record);

 private:
  std::string path_;
  std::ofstream out_;
};

/// \brief Reads a train log.
/// \throws sadsplat::Error naming the file and line when a line is not a record
std::vector<TrainLogRecord> readTrainLog(const std::string& path);

}  // namespace io
}  // namespace sadsplat
