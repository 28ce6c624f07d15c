#include "sadsplat/gaussians/train_config.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "sadsplat/common/error.h"

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

TrainConfig TrainConfig::forGlobalBatch(int views) const {
  if (views < 1)
    throw Error("<config>", "global batch", ">= 1 views per step", std::to_string(views));
  TrainConfig c = *this;
  if (views == 1) return c;
  // Counts round to the nearest step, intervals stay >= 1 (0 and -1 keep their meaning).
  const auto steps = [views](int count) {
    return count <= 0 ? count : std::max(1, static_cast<int>(std::lround(double(count) / views)));
  };
  c.iterations = steps(iterations);
  c.sh_increase_interval = steps(sh_increase_interval);
  c.densify_from = steps(densify_from);
  c.densify_until = steps(densify_until);
  c.densify_interval = steps(densify_interval);
  c.opacity_reset_interval = steps(opacity_reset_interval);
  c.checkpoint_interval = steps(checkpoint_interval);
  c.drop_interval = steps(drop_interval);
  c.recovery_iterations = steps(recovery_iterations);
  c.lambda_l0_from = steps(lambda_l0_from);
  c.lambda_l0_ramp = steps(lambda_l0_ramp);
  const double lr = std::sqrt(static_cast<double>(views));
  for (double* rate :
       {&c.lr_position_init, &c.lr_position_final, &c.lr_sh_dc, &c.lr_sh_rest, &c.lr_opacity,
        &c.lr_scaling, &c.lr_rotation, &c.lr_feature, &c.lr_decoder, &c.lr_log_alpha}) {
    *rate *= lr;
  }
  return c;
}

std::string TrainConfig::toJson() const {
  nlohmann::json j = {{"iterations", iterations},
                      {"feature_dim", feature_dim},
                      {"max_sh_degree", max_sh_degree},
                      {"sh_increase_interval", sh_increase_interval},
                      {"lambda_ssim", lambda_ssim},
                      {"fused_ssim", fused_ssim},
                      {"fused_semantic_loss", fused_semantic_loss},
                      {"lambda_rgb", lambda_rgb},
                      {"lambda_semantic", lambda_semantic},
                      {"semantic_interval", semantic_interval},
                      {"views_per_step", views_per_step},
                      {"prune_floaters", prune_floaters},
                      {"floater_min_views", floater_min_views},
                      {"floater_max_scale", floater_max_scale},
                      {"use_pseudo_labels", use_pseudo_labels},
                      {"lambda_pseudo", lambda_pseudo},
                      {"pseudo_labels_train_decoder", pseudo_labels_train_decoder},
                      {"lr_position_init", lr_position_init},
                      {"lr_position_final", lr_position_final},
                      {"lr_sh_dc", lr_sh_dc},
                      {"lr_sh_rest", lr_sh_rest},
                      {"lr_opacity", lr_opacity},
                      {"lr_scaling", lr_scaling},
                      {"lr_rotation", lr_rotation},
                      {"lr_feature", lr_feature},
                      {"lr_decoder", lr_decoder},
                      {"densify_from", densify_from},
                      {"densify_until", densify_until},
                      {"densify_interval", densify_interval},
                      {"densify_grad_threshold", densify_grad_threshold},
                      {"percent_dense", percent_dense},
                      {"min_opacity", min_opacity},
                      {"opacity_reset_interval", opacity_reset_interval},
                      {"max_screen_radius", max_screen_radius},
                      {"checkpoint_interval", checkpoint_interval},
                      {"seed", seed},
                      {"background", {background[0], background[1], background[2]}},
                      {"device", device},
                      {"max_gaussians", max_gaussians},
                      {"drop", drop},
                      {"p_base", p_base},
                      {"drop_interval", drop_interval},
                      {"lambda_l0", lambda_l0},
                      {"lambda_l0_from", lambda_l0_from},
                      {"lambda_l0_ramp", lambda_l0_ramp},
                      {"l0_importance", l0_importance},
                      {"lr_log_alpha", lr_log_alpha},
                      {"log_alpha_init", log_alpha_init},
                      {"recovery_iterations", recovery_iterations},
                      {"recovery_prune", recovery_prune}};
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
  nlohmann::json defaults = nlohmann::json::parse(c.toJson());
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!defaults.contains(it.key()))
      throw Error(origin, it.key(), "a known configuration key", "unknown");
    if (it.value().type() != defaults[it.key()].type() &&
        !(it.value().is_number() && defaults[it.key()].is_number())) {
      throw Error(origin, it.key(), std::string("a ") + defaults[it.key()].type_name(),
                  it.value().type_name());
    }
    defaults[it.key()] = it.value();
  }
  const auto& d = defaults;
  c.iterations = integer<int>(d, "iterations", origin);
  c.feature_dim = integer<int>(d, "feature_dim", origin);
  c.max_sh_degree = integer<int>(d, "max_sh_degree", origin);
  c.sh_increase_interval = integer<int>(d, "sh_increase_interval", origin);
  c.lambda_ssim = real(d, "lambda_ssim", origin);
  c.fused_ssim = d["fused_ssim"].get<bool>();
  c.fused_semantic_loss = d["fused_semantic_loss"].get<bool>();
  c.lambda_rgb = real(d, "lambda_rgb", origin);
  c.lambda_semantic = real(d, "lambda_semantic", origin);
  c.semantic_interval = integer<int>(d, "semantic_interval", origin);
  c.views_per_step = integer<int>(d, "views_per_step", origin);
  c.prune_floaters = d["prune_floaters"].get<bool>();
  c.floater_min_views = integer<int>(d, "floater_min_views", origin);
  c.floater_max_scale = real(d, "floater_max_scale", origin);
  c.use_pseudo_labels = d["use_pseudo_labels"];
  c.lambda_pseudo = real(d, "lambda_pseudo", origin);
  c.pseudo_labels_train_decoder = d["pseudo_labels_train_decoder"];
  c.lr_position_init = real(d, "lr_position_init", origin);
  c.lr_position_final = real(d, "lr_position_final", origin);
  c.lr_sh_dc = real(d, "lr_sh_dc", origin);
  c.lr_sh_rest = real(d, "lr_sh_rest", origin);
  c.lr_opacity = real(d, "lr_opacity", origin);
  c.lr_scaling = real(d, "lr_scaling", origin);
  c.lr_rotation = real(d, "lr_rotation", origin);
  c.lr_feature = real(d, "lr_feature", origin);
  c.lr_decoder = real(d, "lr_decoder", origin);
  c.densify_from = integer<int>(d, "densify_from", origin);
  c.densify_until = integer<int>(d, "densify_until", origin);
  c.densify_interval = integer<int>(d, "densify_interval", origin);
  c.densify_grad_threshold = real(d, "densify_grad_threshold", origin);
  c.percent_dense = real(d, "percent_dense", origin);
  c.min_opacity = real(d, "min_opacity", origin);
  c.opacity_reset_interval = integer<int>(d, "opacity_reset_interval", origin);
  c.max_screen_radius = integer<int>(d, "max_screen_radius", origin);
  c.checkpoint_interval = integer<int>(d, "checkpoint_interval", origin);
  c.seed = integer<std::uint64_t>(d, "seed", origin);
  const nlohmann::json& background = d["background"];
  if (background.size() != 3) {
    throw Error(origin, "background", "an array of 3 numbers (RGB)",
                std::to_string(background.size()) + " elements");
  }
  for (int k = 0; k < 3; ++k) {
    if (!background[k].is_number()) {
      throw Error(origin, "background", "an array of 3 numbers (RGB)", background[k].type_name());
    }
    c.background[k] = static_cast<float>(background[k].get<double>());
  }
  c.device = d["device"];
  c.max_gaussians = integer<int>(d, "max_gaussians", origin);
  c.drop = d["drop"];
  c.p_base = real(d, "p_base", origin);
  c.drop_interval = integer<int>(d, "drop_interval", origin);
  c.lambda_l0 = real(d, "lambda_l0", origin);
  c.lambda_l0_from = integer<int>(d, "lambda_l0_from", origin);
  c.lambda_l0_ramp = integer<int>(d, "lambda_l0_ramp", origin);
  c.l0_importance = real(d, "l0_importance", origin);
  c.lr_log_alpha = real(d, "lr_log_alpha", origin);
  c.log_alpha_init = real(d, "log_alpha_init", origin);
  c.recovery_iterations = integer<int>(d, "recovery_iterations", origin);
  c.recovery_prune = real(d, "recovery_prune", origin);
  return c;
}

}  // namespace gaussians
}  // namespace sadsplat
