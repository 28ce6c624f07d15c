// `sadsplat train SCENE --out RUN`: train semantic Gaussians. The training flags come from the
// option table (gaussians/train_options.h); a --config JSON file is applied first, flags on top.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../cli_support.h"
#include "commands.h"
#include "sadsplat/distributed/rank_group.h"
#include "sadsplat/gaussians/cpu_threads.h"
#include "sadsplat/gaussians/schedule.h"
#include "sadsplat/gaussians/train_options.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/pipeline/train_run.h"

namespace sadsplat {
namespace cli {
namespace {

class TrainCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("train", "Train semantic Gaussians on a scene");
    c->add_option("SCENE", scene_, "scene directory or scene cache")->required();
    c->add_option("--out", out_, "run directory")->required();
    c->add_option("--config", config_file_, "JSON file with TrainConfig keys (docs: every key)");
    c->add_option("--scale", scale_, "image scale when importing a directory")
        ->capture_default_str();
    c->add_flag("--resume", resume_, "continue from RUN/checkpoint.bin");
    c->add_option("--nproc", nproc_,
                  "data-parallel ranks on this machine (c10d Gloo on CPUs, NCCL with --device "
                  "cuda: one GPU each); or start the ranks with torchrun --no-python, which sets "
                  "RANK / WORLD_SIZE / LOCAL_RANK / MASTER_ADDR / MASTER_PORT. 1: a group of one")
        ->check(CLI::Range(1, 256));
    c->add_flag("--batch-schedule", batch_schedule_,
                "with a global batch of B = ranks x views per step > 1, take the schedule in B "
                "times fewer steps and the learning rates x sqrt(B): as many views seen as one "
                "view per step");
    c->add_option("--schedule", schedule_,
                  "paper: the paper's 7000-iteration schedule (default); long: 30000 iterations, "
                  "densification in the first quarter and, with a drop, gates pushed shut only "
                  "after it and the last sixth refined without gates (scenes whose densification "
                  "levels off; on real surveys it grows larger models than the default; keys you "
                  "set are kept)")
        ->check(CLI::IsMember({"paper", "long"}));
    c->add_flag("--profile", profile_,
                "time each phase of the iterations (waits for the GPU at every phase boundary) "
                "and count its ATen operator calls; writes RUN/profile.md and, operator by "
                "operator, RUN/profile_operators.md");
    c->add_flag("--profile-host", profile_host_,
                "as --profile on the host's clock: no phase waits for the GPU, so each phase "
                "gets the time the CPU spent issuing its work (or waiting for a value)")
        ->excludes("--profile");
    const gaussians::TrainConfig defaults;
    for (const gaussians::TrainOption& o : gaussians::trainOptions()) {
      if (o.flag == nullptr) continue;
      const std::string help = std::string(o.help) + " (config key " + o.key + ", default " +
                               gaussians::optionText(o, defaults) + ")";
      if (std::holds_alternative<bool gaussians::TrainConfig::*>(o.member)) {
        flags_[&o] = c->add_flag(o.flag, help);
        continue;
      }
      CLI::Option* flag = c->add_option(o.flag, values_[&o], help);
      // A value outside the table's range or choices is a usage error (exit 2) here already.
      if (o.choices != nullptr) {
        flag->check(CLI::IsMember(gaussians::optionChoices(o)));
      } else if (!std::holds_alternative<std::string gaussians::TrainConfig::*>(o.member)) {
        const bool real = std::holds_alternative<double gaussians::TrainConfig::*>(o.member);
        flag->type_name(real ? "FLOAT" : "INT");
        if (std::isfinite(o.min) || std::isfinite(o.max)) {
          std::ostringstream range;
          if (!std::isfinite(o.max)) {
            range << ">= " << o.min;
          } else {
            range << o.min << " .. " << o.max;
          }
          flag->check(CLI::Range(o.min, o.max).description(range.str()));
        }
      }
      flags_[&o] = flag;
    }
    return c;
  }

  int run(const Invocation& invocation) override {
    gaussians::TrainConfig config;
    std::vector<std::string> given;  // keys the user set: a short run's schedule keeps them
    if (!config_file_.empty()) {
      const std::string text = io::readWholeFile(config_file_);
      config = gaussians::TrainConfig::fromJson(text, config_file_);
      config.check(config_file_);  // a bad value names the file it came from
      const nlohmann::json keys = nlohmann::json::parse(text);
      for (const auto& item : keys.items()) given.push_back(item.key());
    }
    for (const auto& [option, flag] : flags_) {
      if (flag->count() == 0) continue;
      given.push_back(option->key);
      const bool is_flag = std::holds_alternative<bool gaussians::TrainConfig::*>(option->member);
      gaussians::setOptionFromText(*option, is_flag ? "true" : values_[option], config,
                                   "<command line>");
    }
    // --nproc N starts ranks 1..N-1 as copies of this command (they see RANK and start none).
    std::optional<distributed::LocalRanks> local_ranks;
    if (nproc_ > 0 && std::getenv("RANK") == nullptr) {
      local_ranks.emplace(
          nproc_, std::vector<std::string>(invocation.argv + 1, invocation.argv + invocation.argc));
      gaussians::setCpuThreads();
    }
    const auto rank_env = distributed::RankEnvironment::fromProcessEnvironment();
    const bool quiet_rank = rank_env && rank_env->rank != 0;
    pipeline::TrainRunOptions options;
    options.schedule.kind = gaussians::parseScheduleKind(schedule_);
    options.schedule.given = given;
    if (batch_schedule_) options.schedule.batch_ranks = rank_env ? rank_env->world_size : 1;
    if (rank_env) {
      // Every rank of a group, also a group of one (its all-reduce then costs what it costs).
      if (config.device.rfind("cuda", 0) == 0) distributed::bindLocalGpu(*rank_env);
      options.collective = distributed::joinGroup(*rank_env, config.device);
    }
    options.scene = scene_;
    options.out = out_;
    options.scale = scale_;
    options.resume = resume_;
    if (profile_) options.profile = gaussians::StepProfile::Clock::kDeviceWaited;
    if (profile_host_) options.profile = gaussians::StepProfile::Clock::kHost;
    options.progress = quiet_rank ? nullptr : &std::cout;
    options.stop = &g_stop;
    installStopHandlers();
    const double seconds = pipeline::trainRun(options, config);
    if (local_ranks) local_ranks->waitAll();
    if (!quiet_rank)
      std::cout << "trained in " << seconds << " s; model in " << out_ << "/model.ply\n";
    return 0;
  }

 private:
  std::string scene_, out_, config_file_, schedule_ = "paper";
  double scale_ = 0.5;
  bool resume_ = false, profile_ = false, profile_host_ = false, batch_schedule_ = false;
  int nproc_ = 0;
  std::map<const gaussians::TrainOption*, CLI::Option*> flags_;
  std::map<const gaussians::TrainOption*, std::string> values_;
};

}  // namespace

std::unique_ptr<Command> makeTrainCommand() { return std::make_unique<TrainCommand>(); }

}  // namespace cli
}  // namespace sadsplat
