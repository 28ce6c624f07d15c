#include "training_report.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "sadsplat/gaussians/densification.h"
#include "sadsplat/gaussians/initialization.h"
#include "sadsplat/gaussians/memory_estimate.h"

namespace sadsplat {
namespace pipeline {
namespace {

// The train log's record of an event of step `s`: its type, the iteration, the Gaussians after it
// and how many it removed.
io::TrainLogRecord eventRecord(const char* type, const gaussians::StepStats& s, long long removed) {
  io::TrainLogRecord r;
  r.type = type;
  r.iteration = s.iteration;
  r.removed = removed;
  r.gaussians = s.num_gaussians;
  return r;
}

}  // namespace

std::string formatSeconds(double s) {
  std::ostringstream out;
  const int total = static_cast<int>(std::round(s));
  out << total / 60 << "m" << std::setw(2) << std::setfill('0') << total % 60 << "s";
  return out.str();
}

TrainingReport::TrainingReport(std::ostream* progress, const std::string& log_path, int resumed_at)
    : progress_(progress) {
  if (!log_path.empty()) log_.emplace(log_path, resumed_at);
}

void TrainingReport::started(const io::Scene& scene, const gaussians::TrainConfig& config,
                             bool resume) {
  if (progress_ == nullptr) return;
  std::ostream& out = *progress_;
  if (scene.classes.empty()) {
    out << "RGB only: the scene has no classes.json, so no semantic head (plain 3DGS"
        << (config.drop == gaussians::DropMode::kNone
                ? ""
                : ", drop " + gaussians::choiceName(config.drop) + " without confidence maps")
        << ")\n";
  } else {
    int labelled = 0, pseudo = 0;
    for (const io::View& v : scene.views) {
      if (!v.train) continue;
      if (v.labelled && v.hasLabels())
        ++labelled;
      else if (v.hasPseudoLabels())
        ++pseudo;
    }
    out << "semantic supervision: " << labelled << " labelled views, "
        << (config.use_pseudo_labels ? pseudo : 0) << " pseudo-labelled views"
        << (pseudo == 0 ? " (run `sadsplat pseudo-labels` on the scene cache to add them)" : "")
        << "; drop " << gaussians::choiceName(config.drop) << " with confidence maps of "
        << (pseudo > 0 ? "the pseudo-label backend + ground truth" : "the ground truth only")
        << "\n";
  }
  if (config.device == gaussians::TrainDevice::kCuda) {
    out << "device memory: " << gaussians::estimateTrainingMemory(scene, config).describe() << "\n";
  }
  if (config.lambda_sparse_depth > 0) {
    if (scene.points.empty()) {
      out << "sparse-depth loss: the scene has no sparse points, so lambda_sparse_depth "
          << config.lambda_sparse_depth << " does nothing\n";
    } else {
      out << "sparse-depth loss (weight " << config.lambda_sparse_depth << "): the rendered depth "
          << "against the scene's " << scene.points.size()
          << " sparse points where each training view sees them\n";
    }
  }
  if (!resume && gaussians::initialisesRandomly(config.init, scene.points.size())) {
    out << "initialisation: up to " << config.init_random_count
        << " random points in the training cameras' common view"
        << (config.init == gaussians::InitMode::kRandom ? "" : " (the scene has no sparse points)")
        << "\n";
  }
}

void TrainingReport::schedule(const gaussians::TrainConfig& config) {
  if (progress_) {
    *progress_ << "schedule: " << gaussians::describeDefaultDensification(config) << "\n";
  }
}

void TrainingReport::stepped(const gaussians::StepStats& stats,
                             const gaussians::TrainConfig& config, double seconds) {
  rendered_again_ += stats.rendered_again ? 1 : 0;
  log(stats, seconds, stats.iteration == config.iterations);
  events(stats, config);
  progressLine(stats, config);
}

// The train log's records of one step: a drop and a closed-gate removal when they happened, and
// the losses every 10 iterations (as the progress line) and at the last one.
void TrainingReport::log(const gaussians::StepStats& s, double seconds, bool last) {
  if (!log_) return;
  if (s.dropped > 0) {
    io::TrainLogRecord r = eventRecord("drop", s, s.dropped);
    r.low_confidence = s.drop.removed_low_confidence;
    r.unseen = s.drop.removed_unseen;
    r.closed_gate = s.drop.removed_closed_gate;
    log_->append(r);
  }
  if (s.removed_closed_gates > 0)
    log_->append(eventRecord("closed_gates", s, s.removed_closed_gates));
  if (s.recovery_started) {
    io::TrainLogRecord r = eventRecord("recovery", s, s.recovery_closed_gates + s.recovery_pruned);
    r.closed_gate = s.recovery_closed_gates;
    log_->append(r);
  }
  if (s.losses_read && (s.iteration % kLossInterval == 0 || last)) {
    io::TrainLogRecord r;
    r.iteration = s.iteration;
    r.loss = s.loss;
    r.rgb_loss = s.rgb_loss;
    r.semantic_loss = s.semantic_loss;
    r.gaussians = s.num_gaussians;
    r.seconds = seconds;
    log_->append(r);
  }
}

void TrainingReport::events(const gaussians::StepStats& stats,
                            const gaussians::TrainConfig& config) {
  const int it = stats.iteration;
  // Said once: a model at the cap has stopped growing because of it, not because the densifier
  // converged (a real survey reached 3 M Gaussians by iteration 6000 of the long schedule).
  if (!said_cap_ && stats.num_gaussians >= config.max_gaussians) {
    said_cap_ = true;
    if (log_) log_->append(eventRecord("max_gaussians_reached", stats, 0));
    if (progress_) {
      *progress_ << "\n[densify] iteration " << it << ": the model reached max_gaussians ("
                 << config.max_gaussians << "); densification adds no more. "
                 << io::kMaxGaussiansAdvice << "\n";
    }
  }
  if (progress_ == nullptr) return;
  std::ostream& out = *progress_;
  if (stats.dropped > 0) {
    const gaussians::DropDecision& d = stats.drop;
    out << "\n[drop] iteration " << it << ": removed " << stats.dropped << " Gaussians ("
        << gaussians::choiceName(config.drop) << " " << gaussians::choiceName(config.drop_rule)
        << ", P_base " << config.p_base
        << (config.drop_rule == gaussians::DropRule::kBalanced
                ? ", pressure " + std::to_string(stats.drop_pressure).substr(0, 6)
                : std::string())
        << "), " << stats.num_gaussians << " left; of the removed: " << d.removed_low_confidence
        << " with P_conf < 0.5 (" << d.removed_unseen << " seen by no confidence map), "
        << d.removed_closed_gate << " with P_nonzero < 0.5\n";
  }
  if (stats.removed_closed_gates > 0) {
    out << "\n[drop] end of training: removed " << stats.removed_closed_gates
        << " Gaussians with a closed gate (they render nothing), " << stats.num_gaussians
        << " left\n";
  }
  if (stats.recovery_started) {
    out << "\n[recovery] iteration " << it << ": gates folded into the opacities; removed "
        << stats.recovery_closed_gates << " Gaussians with a closed gate and "
        << stats.recovery_pruned << " least contributing ones, " << stats.num_gaussians << " left; "
        << config.recovery_iterations << " iterations without gates, L0 and drops follow\n";
  }
  if (stats.removed_floaters > 0) {
    std::string rule;
    if (config.floater_min_views > 0) {
      rule = "seen by fewer than " + std::to_string(config.floater_min_views) + " training views";
    }
    if (config.floater_max_scale > 0) {
      std::ostringstream size;
      size << "larger than " << config.floater_max_scale << " x the scene extent";
      rule += (rule.empty() ? "" : " or ") + size.str();
    }
    out << "\n[floaters] end of training: removed " << stats.removed_floaters << " Gaussians "
        << rule << ", " << stats.num_gaussians << " left\n";
  }
}

void TrainingReport::progressLine(const gaussians::StepStats& stats,
                                  const gaussians::TrainConfig& config) {
  if (progress_ == nullptr || !stats.losses_read) return;
  const int it = stats.iteration;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = (it - first_) / std::max(1e-9, elapsed);
  // Formatted apart so that the fixed-point state does not leak into the caller's stream.
  std::ostringstream line;
  line << "\r[" << it << "/" << config.iterations << "] loss " << std::fixed << std::setprecision(4)
       << stats.loss << " (rgb " << stats.rgb_loss << ", sem " << stats.semantic_loss
       << ")  gaussians " << stats.num_gaussians << "  " << std::setprecision(1) << rate
       << " it/s  ETA " << formatSeconds((config.iterations - it) / std::max(rate, 1e-9)) << "   ";
  *progress_ << line.str() << std::flush;
}

void TrainingReport::finished(const gaussians::TrainConfig& config,
                              const std::string& profile_table) {
  if (progress_ == nullptr) return;
  *progress_ << "\n";
  if (rendered_again_ > 0) {
    *progress_ << "[tile lists] " << rendered_again_ << (rendered_again_ == 1 ? " step" : " steps")
               << " rendered again: a tile list sized from earlier renders was short "
                  "(tile_list_margin "
               << config.tile_list_margin << ")\n";
  }
  *progress_ << profile_table;
}

}  // namespace pipeline
}  // namespace sadsplat
