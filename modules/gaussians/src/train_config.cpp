#include "sadsplat/gaussians/train_config.h"

#include "sadsplat/gaussians/train_options.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <type_traits>
#include <variant>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace gaussians {

namespace {

// A whole number in T's range (a JSON float with an integral value counts).
template <typename T>
T integer(const nlohmann::json& d, const char* key, const std::string& origin) {
  const nlohmann::json& v = d[key];
  const auto fail = [&] {
    return Error(origin, key,
                 "a whole number in [" + std::to_string(std::numeric_limits<T>::min()) + ", " +
                     std::to_string(std::numeric_limits<T>::max()) + "]",
                 v.dump());
  };
  if (v.is_number_unsigned()) {
    const std::uint64_t u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) throw fail();
    return static_cast<T>(u);
  }
  if (v.is_number_integer()) {
    const std::int64_t i = v.get<std::int64_t>();
    if (i < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
        (i > 0 && static_cast<std::uint64_t>(i) >
                      static_cast<std::uint64_t>(std::numeric_limits<T>::max()))) {
      throw fail();
    }
    return static_cast<T>(i);
  }
  const double x = v.get<double>();
  // max() + 1 is a power of two, exact as a double; x < it keeps the cast defined.
  const double bound = static_cast<double>(std::numeric_limits<T>::max()) + 1.0;
  if (!std::isfinite(x) || x != std::floor(x) ||
      x < static_cast<double>(std::numeric_limits<T>::min()) || x >= bound) {
    throw fail();
  }
  return static_cast<T>(x);
}

double real(const nlohmann::json& d, const char* key, const std::string& origin) {
  const double x = d[key].get<double>();
  if (!std::isfinite(x)) throw Error(origin, key, "a finite number", d[key].dump());
  return x;
}

}  // namespace

namespace {

using C = TrainConfig;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The table: one row per TrainConfig field. Ranges are what the trainer can run with, not
// recommendations; the defaults are the field initialisers in train_config.h.
const std::vector<TrainOption> kOptions = {
    {"iterations", &C::iterations, "training iterations (paper: 7000)", "--iterations", 1, kInf},
    {"feature_dim", &C::feature_dim, "semantic feature channels per Gaussian (paper: 32)", nullptr,
     0, kFeatureDim},
    {"max_sh_degree", &C::max_sh_degree, "highest spherical-harmonics degree", nullptr, 0, 3},
    {"sh_increase_interval", &C::sh_increase_interval,
     "iterations between raising the SH degree by one", nullptr, 1, kInf},
    {"lambda_ssim", &C::lambda_ssim, "weight of D-SSIM in the RGB loss (paper: 0.2)", nullptr, 0,
     1},
    {"fused_ssim", &C::fused_ssim,
     "the SSIM loss in fused passes, CPU and CUDA (false: the reference composition)"},
    {"fused_semantic_loss", &C::fused_semantic_loss,
     "CUDA: the semantic loss in fused kernels (false: reference)"},
    {"tile_list_margin", &C::tile_list_margin,
     "CUDA: tile lists sized from earlier renders' counts x this, checked after the backward "
     "(0: exact, waiting)",
     nullptr, 0, kInf},
    {"lambda_rgb", &C::lambda_rgb, "weight of the RGB loss", nullptr, 0, kInf},
    {"lambda_semantic", &C::lambda_semantic, "weight of the semantic loss on labelled views",
     nullptr, 0, kInf},
    {"lambda_flatten", &C::lambda_flatten,
     "weight of the flatness loss: mean smallest scale / scene extent (0: off)", nullptr, 0, kInf},
    {"lambda_sparse_depth", &C::lambda_sparse_depth,
     "weight of the sparse-depth loss: mean |rendered depth - sparse point depth| / depth over "
     "the points each training view sees (0: off)",
     nullptr, 0, kInf},
    {"semantic_interval", &C::semantic_interval,
     "every this many iterations a labelled view is rendered as well (0: never)", nullptr, 0, kInf},
    {"views_per_step", &C::views_per_step,
     "training views per step and rank; the loss is their mean", "--views-per-step", 1, 1024},
    {"use_pseudo_labels", &C::use_pseudo_labels,
     "supervise unlabelled training views with the scene's kept pseudo-labels"},
    {"lambda_pseudo", &C::lambda_pseudo, "weight of the semantic loss on pseudo-labelled views",
     nullptr, 0, kInf},
    {"pseudo_labels_train_decoder", &C::pseudo_labels_train_decoder,
     "whether pseudo-labels also train the decoder (paper: yes)"},
    {"lr_position_init", &C::lr_position_init, "position learning rate at the start (x extent)",
     nullptr, 0, kInf},
    {"lr_position_final", &C::lr_position_final, "position learning rate at the end (x extent)",
     nullptr, 0, kInf},
    {"lr_sh_dc", &C::lr_sh_dc, "learning rate of the SH DC coefficients", nullptr, 0, kInf},
    {"lr_sh_rest", &C::lr_sh_rest, "learning rate of the higher SH coefficients", nullptr, 0, kInf},
    {"lr_opacity", &C::lr_opacity, "learning rate of the opacity logits", nullptr, 0, kInf},
    {"lr_scaling", &C::lr_scaling, "learning rate of the log-scales", nullptr, 0, kInf},
    {"lr_rotation", &C::lr_rotation, "learning rate of the quaternions", nullptr, 0, kInf},
    {"lr_feature", &C::lr_feature, "learning rate of the semantic features", nullptr, 0, kInf},
    {"lr_decoder", &C::lr_decoder, "learning rate of the feature decoder", nullptr, 0, kInf},
    {"densify_from", &C::densify_from, "first densification iteration", nullptr, 0, kInf},
    {"densify_until", &C::densify_until, "last densification iteration (-1: 2/7 of the iterations)",
     nullptr, -1, kInf},
    {"densify_interval", &C::densify_interval, "iterations between densifications", nullptr, 1,
     kInf},
    {"densify_grad_threshold", &C::densify_grad_threshold,
     "NDC-space positional gradient that triggers densification (3DGS)", nullptr, 0, kInf},
    {"percent_dense", &C::percent_dense, "clone / split boundary as a share of the extent", nullptr,
     0, kInf},
    {"min_opacity", &C::min_opacity, "Gaussians below this opacity are pruned", nullptr, 0, 1},
    {"opacity_reset_interval", &C::opacity_reset_interval,
     "iterations between opacity resets (0: never)", nullptr, 0, kInf},
    {"max_screen_radius", &C::max_screen_radius,
     "prune Gaussians wider than this many pixels after the first reset (0: off)", nullptr, 0,
     kInf},
    {"checkpoint_interval", &C::checkpoint_interval, "iterations between checkpoints (0: none)",
     nullptr, 0, kInf},
    {"large_split_scale", &C::large_split_scale,
     "after densification, split Gaussians larger than this x the scene extent every "
     "densify_interval (0: off)",
     nullptr, 0, kInf},
    {"large_split_last", &C::large_split_last, "the last iterations without large-Gaussian splits",
     nullptr, 0, kInf},
    {"scale_limit", &C::scale_limit,
     "no Gaussian's scale exceeds this x the scene extent from scale_limit_from on: log-scales "
     "clamped after every step (0: off)",
     "--scale-limit", 0, kInf},
    {"scale_limit_from", &C::scale_limit_from,
     "the iteration from which scale_limit holds; Gaussians above it are split there first (0: "
     "from the start, no split; -1: iterations - iterations / 7, 6000 of 7000)",
     "--scale-limit-from", -1, kInf},
    {"seed", &C::seed, "random seed", "--seed"},
    {"init", &C::init,
     "initial Gaussians: the scene's sparse points, random points in the cameras' common view, or "
     "auto (points when the scene has at least 4, else random)",
     "--init"},
    {"init_random_count", &C::init_random_count, "how many random points --init random places",
     nullptr, 4, kInf},
    {"background", &C::background, "background colour [r, g, b] in [0, 1]"},
    {"device", &C::device, "where to train", "--device"},
    {"stream_views", &C::stream_views,
     "upload each step's views when it renders them, read from the scene cache on loader "
     "threads ahead of the step (an imported directory: kept in host memory in 8 bits): GPU "
     "memory for the model and a step's views, host memory for a few views (the same values)",
     "--stream-views"},
    {"max_gaussians", &C::max_gaussians, "densification stops growing past this", nullptr, 1, kInf},
    {"prune_floaters", &C::prune_floaters,
     "after the last iteration remove Gaussians seen by fewer than floater_min_views training "
     "views or larger than floater_max_scale x the scene extent",
     "--prune-floaters"},
    {"floater_min_views", &C::floater_min_views, "see prune_floaters", nullptr, 0, kInf},
    {"floater_max_scale", &C::floater_max_scale, "see prune_floaters", nullptr, 0, kInf},
    {"drop", &C::drop, "the semantic-aware drop", "--drop"},
    {"p_base", &C::p_base, "base drop rate P_base (paper: 1.0)", "--p-base", 0, kInf},
    {"drop_interval", &C::drop_interval, "iterations between drops (paper: 500)", nullptr, 1, kInf},
    {"lambda_l0", &C::lambda_l0, "weight of the L0 sparsity loss", "--lambda-l0", 0, kInf},
    {"lambda_l0_from", &C::lambda_l0_from,
     "the L0 loss starts at this iteration; balanced rule: its first drop event too (not the "
     "paper; "
     "0: from the start)",
     "--lambda-l0-from", 0, kInf},
    {"lambda_l0_ramp", &C::lambda_l0_ramp,
     "the L0 weight rises linearly over this many iterations (0: at once)", "--lambda-l0-ramp", 0,
     kInf},
    {"l0_importance", &C::l0_importance,
     "weight the L0 loss towards the Gaussians that contribute least, exponent gamma (not the "
     "paper; 0: the plain mean)",
     "--l0-importance", 0, kInf},
    {"lr_log_alpha", &C::lr_log_alpha, "learning rate of the Hard Concrete gates", nullptr, 0,
     kInf},
    {"log_alpha_init", &C::log_alpha_init, "initial gate log-alpha (3: P(open) = 0.99)"},
    {"recovery_iterations", &C::recovery_iterations,
     "the last N iterations train without gates, L0 and drops (not the paper; 0: off)",
     "--recovery", 0, kInf},
    {"recovery_prune", &C::recovery_prune,
     "at the start of the recovery also remove this share of the least contributing Gaussians",
     "--recovery-prune", 0, 0.999},
    {"drop_rule", &C::drop_rule,
     "balanced: L0 force relative to the RGB force, capped drop events, a loss guard (not the "
     "paper); paper: the paper's rule as printed",
     "--drop-rule"},
    {"l0_strength", &C::l0_strength,
     "balanced rule: L0 force on a gate as a share of the mean RGB force on the gates",
     "--l0-strength", 0, kInf},
    {"drop_max_fraction", &C::drop_max_fraction,
     "balanced rule: the largest share of the Gaussians one drop event removes", nullptr, 0, 1},
    {"drop_guard", &C::drop_guard,
     "balanced rule: relative rise of the mean squared error of four fixed training views "
     "(rendered as for evaluation) from one drop event to the next that halves the L0 strength "
     "and the cap; not across an opacity reset (0: off)",
     nullptr, 0, kInf},
    {"closed_gate_gradients", &C::closed_gate_gradients,
     "gates closed in a step's sample still get the render's gradient at 0 (MaskGaussian's "
     "masked rasterisation; not the paper)",
     "--closed-gate-gradients"},
};

// The value of a choice named by a JSON string.
template <typename Choice>
Choice choiceNamed(const nlohmann::json& value, const char* key, const std::string& origin) {
  if (!value.is_string()) throw Error(origin, key, "a string", value.type_name());
  return parseChoice<Choice>(value.get<std::string>(), origin, key);
}

std::string numberText(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// Sets the option from a JSON value, with the reader's type and integer checks.
void setFromJson(const TrainOption& o, const nlohmann::json& value, TrainConfig& c,
                 const std::string& origin) {
  nlohmann::json d = {{o.key, value}};
  std::visit(
      [&](auto member) {
        using T = std::decay_t<decltype(c.*member)>;
        if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::uint64_t>) {
          c.*member = integer<T>(d, o.key, origin);
        } else if constexpr (std::is_same_v<T, double>) {
          c.*member = real(d, o.key, origin);
        } else if constexpr (std::is_same_v<T, bool>) {
          c.*member = value.get<T>();
        } else if constexpr (std::is_enum_v<T>) {
          c.*member = choiceNamed<T>(value, o.key, origin);
        } else {  // the background colour
          if (!value.is_array() || value.size() != 3) {
            throw Error(
                origin, o.key, "an array of 3 numbers (RGB)",
                value.is_array() ? std::to_string(value.size()) + " elements" : value.type_name());
          }
          for (int k = 0; k < 3; ++k) {
            if (!value[k].is_number()) {
              throw Error(origin, o.key, "an array of 3 numbers (RGB)", value[k].type_name());
            }
            (c.*member)[k] = static_cast<float>(value[k].get<double>());
          }
        }
      },
      o.member);
}

nlohmann::json toJsonValue(const TrainOption& o, const TrainConfig& c) {
  return std::visit(
      [&](auto member) -> nlohmann::json {
        using T = std::decay_t<decltype(c.*member)>;
        if constexpr (std::is_same_v<T, std::array<float, 3>>) {
          return {(c.*member)[0], (c.*member)[1], (c.*member)[2]};
        } else if constexpr (std::is_enum_v<T>) {
          return choiceName(c.*member);
        } else {
          return c.*member;
        }
      },
      o.member);
}

}  // namespace

const std::vector<TrainOption>& trainOptions() { return kOptions; }

const std::vector<std::string>& choiceNames(DropMode) {
  static const std::vector<std::string> names{"none", "semantic", "structure", "full"};
  return names;
}
const std::vector<std::string>& choiceNames(DropRule) {
  static const std::vector<std::string> names{"balanced", "paper"};
  return names;
}
const std::vector<std::string>& choiceNames(InitMode) {
  static const std::vector<std::string> names{"auto", "points", "random"};
  return names;
}
const std::vector<std::string>& choiceNames(TrainDevice) {
  static const std::vector<std::string> names{"cpu", "cuda"};
  return names;
}

template <typename Choice>
Choice parseChoice(const std::string& name, const std::string& origin, const std::string& key) {
  const std::vector<std::string>& names = choiceNames(Choice{});
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    std::string expected;
    for (const std::string& n : names) expected += (expected.empty() ? "" : ",") + n;
    throw Error(origin, key, expected, name);
  }
  return static_cast<Choice>(it - names.begin());
}
template DropMode parseChoice(const std::string&, const std::string&, const std::string&);
template DropRule parseChoice(const std::string&, const std::string&, const std::string&);
template InitMode parseChoice(const std::string&, const std::string&, const std::string&);
template TrainDevice parseChoice(const std::string&, const std::string&, const std::string&);

std::vector<std::string> optionChoices(const TrainOption& option) {
  return std::visit(
      [](auto member) -> std::vector<std::string> {
        using T = std::decay_t<decltype(TrainConfig{}.*member)>;
        if constexpr (std::is_enum_v<T>) {
          return choiceNames(T{});
        } else {
          return {};
        }
      },
      option.member);
}

std::string optionText(const TrainOption& option, const TrainConfig& config) {
  const nlohmann::json v = toJsonValue(option, config);
  return v.is_string() ? v.get<std::string>() : v.dump();
}

void setOptionFromText(const TrainOption& option, const std::string& text, TrainConfig& config,
                       const std::string& origin) {
  nlohmann::json value;
  if (!optionChoices(option).empty()) {
    value = text;
  } else {
    value = nlohmann::json::parse(text, nullptr, false);
    if (value.is_discarded() || value.is_string()) {
      throw Error(
          origin, option.flag ? option.flag : option.key,
          std::holds_alternative<bool TrainConfig::*>(option.member) ? "true or false" : "a number",
          text);
    }
  }
  const nlohmann::json reference = toJsonValue(option, TrainConfig{});
  if (value.type() != reference.type() && !(value.is_number() && reference.is_number())) {
    throw Error(origin, option.flag ? option.flag : option.key,
                std::string("a ") + reference.type_name(), value.type_name());
  }
  setFromJson(option, value, config, origin);
}

void TrainConfig::check(const std::string& origin) const {
  for (const TrainOption& o : kOptions) {
    const nlohmann::json v = toJsonValue(o, *this);
    if (v.is_number() && !(v.get<double>() >= o.min && v.get<double>() <= o.max)) {
      const std::string range = o.max == kInf    ? ">= " + numberText(o.min)
                                : o.min == -kInf ? "<= " + numberText(o.max)
                                                 : numberText(o.min) + " .. " + numberText(o.max);
      throw Error(origin, o.key, range, v.dump());
    }
  }
  if (tile_list_margin > 0 && tile_list_margin < 1) {
    throw Error(origin, "tile_list_margin", "0 (exact lists) or >= 1",
                numberText(tile_list_margin));
  }
  if (recovery_iterations >= iterations) {
    throw Error(origin, "recovery_iterations", "0 .. iterations - 1",
                std::to_string(recovery_iterations));
  }
}

std::string TrainConfig::toJson() const {
  nlohmann::json j = nlohmann::json::object();
  for (const TrainOption& o : kOptions) j[o.key] = toJsonValue(o, *this);
  return j.dump(2) + "\n";
}

TrainConfig TrainConfig::fromJson(const std::string& text, const std::string& origin) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // parse_error, or out_of_range for 1e99999
    throw Error(origin, "JSON syntax", "valid JSON", e.what());
  }
  if (!j.is_object()) throw Error(origin, "top level", "a JSON object", j.type_name());
  TrainConfig c;
  const nlohmann::json defaults = nlohmann::json::parse(c.toJson());
  for (auto it = j.begin(); it != j.end(); ++it) {
    const auto option = std::find_if(kOptions.begin(), kOptions.end(),
                                     [&](const TrainOption& o) { return it.key() == o.key; });
    if (option == kOptions.end()) {
      throw Error(origin, it.key(), "a known configuration key", "unknown");
    }
    const nlohmann::json& reference = defaults[it.key()];
    if (it.value().type() != reference.type() &&
        !(it.value().is_number() && reference.is_number())) {
      throw Error(origin, it.key(), std::string("a ") + reference.type_name(),
                  it.value().type_name());
    }
    setFromJson(*option, it.value(), c, origin);
  }
  return c;
}

}  // namespace gaussians
}  // namespace sadsplat
