#include "sadsplat/io/train_log.h"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {
namespace {

// A line as JSON, or a discarded value: nlohmann throws out_of_range (not a discarded value) for
// numbers that overflow a double, even when asked not to throw (found by fuzzing).
nlohmann::json parseLine(const std::string& line) {
  try {
    return nlohmann::json::parse(line, nullptr, false);
  } catch (const nlohmann::json::exception&) {
    return nlohmann::json(nlohmann::json::value_t::discarded);
  }
}

}  // namespace

TrainLogWriter::TrainLogWriter(const std::string& path, int resume_iteration) : path_(path) {
  std::string kept;
  if (resume_iteration >= 0 && isRegularFile(path)) {
    std::istringstream lines(readWholeFile(path));
    for (std::string line; std::getline(lines, line);) {
      const auto j = parseLine(line);
      if (j.is_discarded() || !j.is_object()) continue;  // a line cut short by a crash
      const auto it = j.find("iteration");
      if (it != j.end() && it->is_number() && it->get<double>() <= resume_iteration) {
        kept += line + "\n";
      }
    }
  }
  writeTextFileAtomically(path, kept);
  out_.open(path, std::ios::app);
  if (!out_) throw Error(path, "open for appending", "a writable file", std::strerror(errno));
}

void TrainLogWriter::append(const TrainLogRecord& r) {
  nlohmann::json j = {{"type", r.type}, {"iteration", r.iteration}, {"gaussians", r.gaussians}};
  if (r.type == "step") {
    j["loss"] = r.loss;
    j["rgb_loss"] = r.rgb_loss;
    j["semantic_loss"] = r.semantic_loss;
    j["seconds"] = r.seconds;
  } else if (r.type != "max_gaussians_reached") {
    j["removed"] = r.removed;
  }
  if (r.type == "recovery") j["closed_gate"] = r.closed_gate;
  if (r.type == "drop") {
    j["low_confidence"] = r.low_confidence;
    j["unseen"] = r.unseen;
    j["closed_gate"] = r.closed_gate;
  }
  out_ << j.dump() << "\n" << std::flush;
  if (!out_) throw Error(path_, "write", "all bytes written", "a stream error (disk full?)");
}

std::vector<TrainLogRecord> readTrainLog(const std::string& path) {
  std::vector<TrainLogRecord> records;
  std::istringstream lines(readWholeFile(path));
  int line_no = 0;
  for (std::string line; std::getline(lines, line);) {
    ++line_no;
    if (line.empty()) continue;
    const auto j = parseLine(line);
    if (j.is_discarded() || !j.is_object() || !j.contains("type") || !j["type"].is_string() ||
        !j.contains("iteration") || !j["iteration"].is_number_integer() ||
        std::abs(j["iteration"].get<double>()) > 2e9) {
      throw Error(path, "line " + std::to_string(line_no),
                  "a JSON object with \"type\" and an integer \"iteration\"", line.substr(0, 60));
    }
    const auto number = [&](const char* key) {
      return j.contains(key) && j[key].is_number() ? j[key].get<double>() : 0.0;
    };
    // Counts: whole numbers in [0, 2^53], checked before the conversion (a double beyond the
    // range of long long converts with undefined behaviour; found by fuzzing).
    const auto count = [&](const char* key) {
      const double v = number(key);
      if (!(v >= 0 && v <= 9007199254740992.0) || v != std::floor(v)) {
        throw Error(path, "line " + std::to_string(line_no) + " " + key,
                    "a count (a whole number >= 0)", std::to_string(v));
      }
      return static_cast<long long>(v);
    };
    TrainLogRecord r;
    r.type = j["type"].get<std::string>();
    r.iteration = j["iteration"].get<int>();
    r.loss = number("loss");
    r.rgb_loss = number("rgb_loss");
    r.semantic_loss = number("semantic_loss");
    r.seconds = number("seconds");
    r.gaussians = count("gaussians");
    r.removed = count("removed");
    r.low_confidence = count("low_confidence");
    r.unseen = count("unseen");
    r.closed_gate = count("closed_gate");
    records.push_back(r);
  }
  return records;
}

}  // namespace io
}  // namespace sadsplat
