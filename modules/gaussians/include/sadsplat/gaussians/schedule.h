#pragma once
/// \file schedule.h
/// \brief The one place where a run's schedule is resolved: the long schedule, the short-run
/// rules, the global-batch scaling and the keys whose -1 means "from the number of iterations".
/// `sadsplat train`, `sadsplat demo` and pipeline::trainRun call resolveSchedule once; its result
/// is what the trainer runs, what the terminal shows and what config.json records. No LibTorch.

#include <string>
#include <vector>

#include "sadsplat/gaussians/train_config.h"

namespace sadsplat {
namespace gaussians {

/// \brief `sadsplat train --schedule`.
enum class ScheduleKind {
  kPaper,  ///< the paper's 7000 iterations (shorter runs take the short-run rules)
  kLong,   ///< longSchedule
};

/// \brief The schedule kind named `text` ("paper" or "long").
/// \throws sadsplat::Error naming `origin`
ScheduleKind parseScheduleKind(const std::string& text, const std::string& origin = "--schedule");

/// \brief What a run asks of the schedule beyond its configuration.
struct ScheduleRequest {
  ScheduleKind kind = ScheduleKind::kPaper;
  /// Keys the user set (in a file or by a flag): no rule changes them.
  std::vector<std::string> given;
  /// Data-parallel ranks of a run that takes the schedule in global batches (forGlobalBatch of
  /// views_per_step x ranks); 0: no batch rule.
  int batch_ranks = 0;
};

/// \brief A schedule resolved: the configuration the trainer runs (densify_until and
/// scale_limit_from are never -1 in it) and one line per rule that changed keys.
struct ResolvedSchedule {
  TrainConfig config;
  std::vector<std::string> notes;
};

/// \brief Applies, in this order, the long schedule (kind kLong), the short-run rules, the
/// global batch (batch_ranks > 0) and resolveDerivedKeys; checks the result.
/// \throws sadsplat::Error when a rule leaves an option out of its range
ResolvedSchedule resolveSchedule(const TrainConfig& config, const ScheduleRequest& request = {});

/// \brief The keys whose -1 means "from the number of iterations", resolved: densify_until
/// (densifyUntilResolved) and scale_limit_from (iterations - iterations / 7). Resolving twice
/// changes nothing; the trainer applies it to any configuration it is given.
TrainConfig resolveDerivedKeys(TrainConfig config);

/// \brief densify_until as the trainer runs it: a set value, or for -1 2/7 of the iterations
/// (2000 of 7000). Not 3DGS's half: at 7000 iterations half puts the opacity reset at 3000
/// 500 iterations before the densification ends, and that reset cost Net-1 1.2-2.3 dB on the
/// benchmark scenes and 0.5-0.8 dB on a real survey; stopping at 2000 recovered it and halved
/// the real survey's dropped model (docs/measurements/gpu_shorter_densification).
int densifyUntilResolved(const TrainConfig& config);

/// \brief The same training for a global batch of `views` training views per step (ranks x
/// views_per_step): every iteration count of the schedule (iterations, densification, opacity
/// reset, SH increase, drop, checkpoints) divided by `views`, so that the run sees as many
/// views as this one, and every learning rate times sqrt(views) (the square-root rule for
/// Adam that Grendel uses for batched 3DGS). views = 1 returns `config`.
/// \throws sadsplat::Error when views < 1
TrainConfig forGlobalBatch(const TrainConfig& config, int views);

/// \brief The schedule of a run shorter than the paper's 7000 iterations: the SH degree rises
/// every iterations / 4, densification starts by iterations / 10 and (densify_until -1) lasts
/// half the run, no opacity reset falls inside the run, drops come every iterations / 4 at most;
/// each only where the default would not fit and the key is not in `given` (keys the user set).
/// Returns `config` for longer runs.
/// \param[out] changed if not null, "key default -> value" for each key it changed
TrainConfig shortRunSchedule(const TrainConfig& config, const std::vector<std::string>& given,
                             std::vector<std::string>* changed = nullptr);

/// \brief The long schedule (`sadsplat train --schedule long`, not the paper), for scenes whose
/// densification levels off (on a real survey whose densifier grows to max_gaussians it gives
/// larger models than the paper schedule; docs/measurements/gpu_long_schedule): 30000
/// iterations, densification in the first quarter (densify_until = iterations / 4; 3DGS
/// densifies for half); with a drop, the gates are pushed shut only after the densification
/// (lambda_l0_from = densify_until) and the last iterations / 6 refine the model without gates
/// (recovery_iterations): prune, then refine, as the pruning work that reaches >= 10x does.
/// Each key only where it is not in `given` (keys the user set; a given `iterations` sets the
/// length the others follow).
/// \param[out] changed if not null, "key default -> value" for each key it changed
TrainConfig longSchedule(const TrainConfig& config, const std::vector<std::string>& given,
                         std::vector<std::string>* changed = nullptr);

}  // namespace gaussians
}  // namespace sadsplat
