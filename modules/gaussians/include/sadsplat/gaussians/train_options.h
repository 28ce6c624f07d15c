#pragma once
/// \file train_options.h
/// \brief The one table of training options: each TrainConfig field once, with its JSON key,
/// help text, optional command-line flag and the range it must lie in. The JSON reader and
/// writer, TrainConfig::check and the `sadsplat train` flags are all driven by it, so an option
/// is added in one place (COLMAP's OptionManager is the model). No LibTorch here.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "sadsplat/gaussians/train_config.h"

namespace sadsplat {
namespace gaussians {

/// \brief One option: where it lives in TrainConfig and what it accepts.
struct TrainOption {
  using Member =
      std::variant<int TrainConfig::*, double TrainConfig::*, bool TrainConfig::*,
                   std::uint64_t TrainConfig::*, std::array<float, 3> TrainConfig::*,
                   DropMode TrainConfig::*, DropRule TrainConfig::*, InitMode TrainConfig::*,
                   TrainDevice TrainConfig::*>;
  const char* key;   ///< JSON key (snake_case)
  Member member;     ///< the TrainConfig field
  const char* help;  ///< one line for --help and the docs; no measured results here
  const char* flag = nullptr;  ///< `sadsplat train` flag ("--lambda-l0"), nullptr: JSON only
  double min = -std::numeric_limits<double>::infinity();  ///< numbers: smallest accepted
  double max = std::numeric_limits<double>::infinity();   ///< numbers: largest accepted
};

/// \brief Every training option, in documentation order.
const std::vector<TrainOption>& trainOptions();

/// \brief The accepted names of a choice (an enum option; empty for the others).
std::vector<std::string> optionChoices(const TrainOption& option);

/// \brief The option's value in `config` as text ("0.2", "true", "cpu", "[0, 0, 0]").
std::string optionText(const TrainOption& option, const TrainConfig& config);

/// \brief Sets the option in `config` from command-line text (a number, true/false or a word),
/// with the JSON reader's type checks.
/// \throws sadsplat::Error naming `origin` and the flag
void setOptionFromText(const TrainOption& option, const std::string& text, TrainConfig& config,
                       const std::string& origin);

}  // namespace gaussians
}  // namespace sadsplat
