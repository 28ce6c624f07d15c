#pragma once
// JSON of the run files the viz module reads (run.json, metrics.json).
#include <nlohmann/json.hpp>

#include <string>

namespace sadsplat {
namespace viz {

// JSON text, or a discarded value when it is not JSON: nlohmann throws out_of_range for numbers
// that overflow a double even when asked not to throw (found by fuzzing the train log).
inline nlohmann::json parseOrDiscard(const std::string& text) {
  try {
    return nlohmann::json::parse(text, nullptr, false);
  } catch (const nlohmann::json::exception&) {
    return nlohmann::json(nlohmann::json::value_t::discarded);
  }
}

}  // namespace viz
}  // namespace sadsplat
