#include "sadsplat/gaussians/schedule.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {
namespace {

// A schedule's change of one key: `member` becomes `value` unless the user gave `key`; each
// change is noted in `changed` (if not null) as "key old -> new".
class ScheduleKeys {
 public:
  ScheduleKeys(const std::vector<std::string>& given, std::vector<std::string>* changed)
      : given_(given), changed_(changed) {}
  void set(const char* key, int& member, int value) const {
    if (std::find(given_.begin(), given_.end(), key) != given_.end() || member == value) return;
    if (changed_) {
      changed_->push_back(std::string(key) + " " + std::to_string(member) + " -> " +
                          std::to_string(value));
    }
    member = value;
  }

 private:
  const std::vector<std::string>& given_;
  std::vector<std::string>* changed_;
};

std::string joined(const std::vector<std::string>& changes) {
  std::string line;
  for (const std::string& c : changes) line += " " + c + ";";
  return line;
}

}  // namespace

ScheduleKind parseScheduleKind(const std::string& text, const std::string& origin) {
  if (text == "paper") return ScheduleKind::kPaper;
  if (text == "long") return ScheduleKind::kLong;
  throw Error(origin, "schedule", "paper or long", text);
}

ResolvedSchedule resolveSchedule(const TrainConfig& config, const ScheduleRequest& request) {
  ResolvedSchedule r;
  r.config = config;
  if (request.kind == ScheduleKind::kLong) {
    std::vector<std::string> changed;
    r.config = longSchedule(r.config, request.given, &changed);
    r.notes.push_back("long schedule:" + joined(changed) + " (set a key to keep its value)");
    r.config.check("--schedule long");
  }
  std::vector<std::string> changed;
  r.config = shortRunSchedule(r.config, request.given, &changed);
  if (!changed.empty()) {
    r.notes.push_back("schedule of a run of " + std::to_string(r.config.iterations) +
                      " iterations:" + joined(changed) + " (set a key to keep its value)");
  }
  if (request.batch_ranks > 0) {
    const int views = r.config.views_per_step * request.batch_ranks;
    r.config = forGlobalBatch(r.config, views);
    if (views > 1) {
      r.notes.push_back("global batch of " + std::to_string(views) +
                        " views per step: every iteration count / " + std::to_string(views) +
                        ", learning rates x sqrt(" + std::to_string(views) + ")");
    }
  }
  r.config = resolveDerivedKeys(r.config);
  r.config.check("the resolved schedule");
  return r;
}

TrainConfig resolveDerivedKeys(TrainConfig c) {
  c.densify_until = densifyUntilResolved(c);
  if (c.scale_limit_from < 0) c.scale_limit_from = c.iterations - c.iterations / 7;
  return c;
}

int densifyUntilResolved(const TrainConfig& c) {
  if (c.densify_until >= 0) return c.densify_until;
  return static_cast<int>(std::int64_t{c.iterations} * 2 / 7);
}

TrainConfig forGlobalBatch(const TrainConfig& config, int views) {
  if (views < 1)
    throw Error("<config>", "global batch", ">= 1 views per step", std::to_string(views));
  TrainConfig c = config;
  if (views == 1) return c;
  // Counts round to the nearest step, intervals stay >= 1 (0 and -1 keep their meaning).
  const auto steps = [views](int count) {
    return count <= 0 ? count : std::max(1, static_cast<int>(std::lround(double(count) / views)));
  };
  for (int* count :
       {&c.iterations, &c.sh_increase_interval, &c.densify_from, &c.densify_until,
        &c.densify_interval, &c.opacity_reset_interval, &c.checkpoint_interval, &c.drop_interval,
        &c.recovery_iterations, &c.lambda_l0_from, &c.lambda_l0_ramp, &c.scale_limit_from}) {
    *count = steps(*count);
  }
  const double lr = std::sqrt(static_cast<double>(views));
  for (double* rate :
       {&c.lr_position_init, &c.lr_position_final, &c.lr_sh_dc, &c.lr_sh_rest, &c.lr_opacity,
        &c.lr_scaling, &c.lr_rotation, &c.lr_feature, &c.lr_decoder, &c.lr_log_alpha}) {
    *rate *= lr;
  }
  return c;
}

TrainConfig shortRunSchedule(const TrainConfig& config, const std::vector<std::string>& given,
                             std::vector<std::string>* changed) {
  TrainConfig c = config;
  const int iterations = config.iterations;
  if (iterations >= 7000) return c;
  const ScheduleKeys keys(given, changed);
  keys.set("sh_increase_interval", c.sh_increase_interval,
           std::min(config.sh_increase_interval, std::max(1, iterations / 4)));
  keys.set("densify_from", c.densify_from, std::min(config.densify_from, iterations / 10));
  keys.set("opacity_reset_interval", c.opacity_reset_interval,
           std::max(iterations, config.opacity_reset_interval));
  keys.set("drop_interval", c.drop_interval,
           std::min(config.drop_interval, std::max(1, iterations / 4)));
  if (c.densify_until < 0) keys.set("densify_until", c.densify_until, iterations / 2);
  return c;
}

TrainConfig longSchedule(const TrainConfig& config, const std::vector<std::string>& given,
                         std::vector<std::string>* changed) {
  TrainConfig c = config;
  const ScheduleKeys keys(given, changed);
  keys.set("iterations", c.iterations, 30000);
  // Densify for the first quarter, then refine (city 0, 30000 iterations: until 7500 gave more
  // PSNR than until 15000, 3DGS's half, with and without a drop; docs/measurements/
  // gpu_long_schedule).
  keys.set("densify_until", c.densify_until, c.iterations / 4);
  if (c.drop != DropMode::kNone) {
    keys.set("lambda_l0_from", c.lambda_l0_from, densifyUntilResolved(c));
    keys.set("recovery_iterations", c.recovery_iterations, c.iterations / 6);
  }
  return c;
}

}  // namespace gaussians
}  // namespace sadsplat
