// `sadsplat train SCENE --out RUN`: train semantic Gaussians. The training flags come from the
// option table (gaussians/train_options.h); a --config JSON file is applied first, flags on top.
#include <sys/resource.h>

#include <chrono>
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
#include "sadsplat/pipeline/block_run.h"
#include "sadsplat/pipeline/train_run.h"

namespace sadsplat {
namespace cli {
namespace {

// This process's peak resident host memory (the kernel's high-water mark).
std::string peakHostMemoryText() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return "peak host memory unknown";
  return "peak host memory " + std::to_string(usage.ru_maxrss / 1024) + " MiB";  // KiB on Linux
}

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
    c->add_option("--blocks", blocks_text_,
                  "N or auto: train the scene in N blocks on its ground plane, one after another "
                  "(or shared by the --nproc ranks), each on the views that see it, and merge "
                  "them into one model; auto: the fewest blocks whose training fits "
                  "--max-gpu-memory (docs/GUIDE.md: surveys larger than your GPU)")
        ->check(CLI::IsMember({"auto"}) | CLI::Range(1, 4096));
    c->add_option("--max-gpu-memory", max_gpu_memory_gib_,
                  "GiB a training may hold on its device (estimated from the views, the sparse "
                  "points and the configuration): cut the scene into as few blocks as fit (implies "
                  "--blocks auto; with --blocks N, at least N blocks)")
        ->check(CLI::Range(1.0e-6, 1.0e6));
    c->add_option("--block-overlap", block_options_.overlap,
                  "with --blocks: a block's cell grown by this share of its size on each side")
        ->check(CLI::Range(0.0, 1.0))
        ->capture_default_str();
    c->add_option("--block-view-share", block_options_.view_share,
                  "with --blocks: a view trains a block when this share of the sparse points it "
                  "sees lie in the block's grown cell (labelled views: "
                  "--block-labelled-view-share)")
        ->check(CLI::Range(0.001, 1.0))
        ->capture_default_str();
    c->add_option("--block-labelled-view-share", block_options_.labelled_view_share,
                  "with --blocks: the same share for a labelled view")
        ->check(CLI::Range(0.001, 1.0))
        ->capture_default_str();
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
      if (!gaussians::optionChoices(o).empty()) {
        flag->check(CLI::IsMember(gaussians::optionChoices(o)));
      } else {
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
    if (rank_env && config.device == gaussians::TrainDevice::kCuda) {
      distributed::bindLocalGpu(*rank_env);
    }
    // A budget alone means --blocks auto.
    if (max_gpu_memory_gib_ > 0 && blocks_text_.empty()) blocks_text_ = "auto";
    const bool in_blocks = !blocks_text_.empty();
    if (blocks_text_ == "auto" && max_gpu_memory_gib_ <= 0)
      throw Error("<command line>", "--max-gpu-memory",
                  "a budget in GiB with --blocks auto (e.g. --max-gpu-memory 22 for a 24 GB card)",
                  "none");
    if (rank_env && !in_blocks) {
      // Every rank of a group, also a group of one (its all-reduce then costs what it costs).
      options.collective = distributed::joinGroup(*rank_env, gaussians::choiceName(config.device));
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
    if (in_blocks) return trainInBlocks(options, config, rank_env, local_ranks);
    const double seconds = pipeline::trainRun(options, config);
    if (local_ranks) local_ranks->waitAll();
    if (!quiet_rank)
      std::cout << "trained in " << seconds << " s; model in " << out_ << "/model.ply; "
                << peakHostMemoryText() << "\n";
    return 0;
  }

 private:
  // --blocks: each rank trains its blocks on its own; rank 0 merges once all have finished.
  int trainInBlocks(const pipeline::TrainRunOptions& options, const gaussians::TrainConfig& config,
                    const std::optional<distributed::RankEnvironment>& rank_env,
                    std::optional<distributed::LocalRanks>& local_ranks) {
    if (batch_schedule_)
      throw Error("<command line>", "--batch-schedule",
                  "no --blocks (the global batch is data-parallel training's; a block trains on "
                  "one rank)",
                  "both");
    pipeline::BlockRunOptions blocks;
    blocks.partition = block_options_;
    blocks.partition.blocks = 0;
    if (blocks_text_ != "auto") {
      std::size_t end = 0;
      blocks.partition.blocks = std::stoi(blocks_text_, &end);
      if (end != blocks_text_.size())
        throw Error("<command line>", "--blocks", "a whole number or auto", blocks_text_);
    }
    if (max_gpu_memory_gib_ > 0) {  // with --blocks N: at least N blocks
      blocks.max_device_bytes = static_cast<std::int64_t>(max_gpu_memory_gib_ * (1ll << 30));
      blocks.budget_config = gaussians::resolveSchedule(config, options.schedule).config;
    }
    blocks.rank = rank_env ? rank_env->rank : 0;
    blocks.ranks = rank_env ? rank_env->world_size : 1;
    blocks.wait_for_ranks = !local_ranks && blocks.ranks > 1;
    const auto start = std::chrono::steady_clock::now();
    pipeline::BlockRun run(options, blocks);
    run.train(config);
    if (local_ranks) local_ranks->waitAll();
    if (blocks.rank != 0) return 0;
    run.merge();
    std::cout << "trained in " << run.partition().blocks.size() << " blocks in "
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
              << " s; model in " << out_ << "/model.ply; " << peakHostMemoryText() << "\n";
    return 0;
  }

  std::string scene_, out_, config_file_, schedule_ = "paper";
  double scale_ = 0.5;
  bool resume_ = false, profile_ = false, profile_host_ = false, batch_schedule_ = false;
  int nproc_ = 0;
  std::string blocks_text_;  // N or auto; empty: no blocks
  double max_gpu_memory_gib_ = 0;
  geo::BlockOptions block_options_;
  std::map<const gaussians::TrainOption*, CLI::Option*> flags_;
  std::map<const gaussians::TrainOption*, std::string> values_;
};

}  // namespace

std::unique_ptr<Command> makeTrainCommand() { return std::make_unique<TrainCommand>(); }

}  // namespace cli
}  // namespace sadsplat
