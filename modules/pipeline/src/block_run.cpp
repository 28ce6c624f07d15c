#include "sadsplat/pipeline/block_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <thread>
#include <utility>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/block_merge.h"
#include "sadsplat/gaussians/memory_estimate.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/semantic_drop/drop_strategy.h"

namespace sadsplat {
namespace pipeline {
namespace {

// Whether a block's run directory holds its finished training.
bool finished(const io::RunDirectory& dir, int iterations) {
  return io::RunDirectory::isRun(dir.path()) && io::RunDirectory::hasCheckpoint(dir.path()) &&
         dir.readRecord(false).iterations >= iterations;
}

void sayBlock(std::ostream* out, const geo::Block& block, const geo::BlockPartition& p,
              const io::Scene& scene, const std::string& what) {
  if (out == nullptr) return;
  *out << "block " << block.index + 1 << "/" << p.blocks.size() << " (row " << block.row
       << ", column " << block.column << "): " << block.views.size() << " views ("
       << block.labelledViews(scene) << " labelled), " << block.points.size()
       << " sparse points: " << what << "\n";
  if (scene.classes.empty() || (what != "training" && what != "resuming")) return;
  const bool supervised = std::any_of(block.views.begin(), block.views.end(), [&](int v) {
    return scene.views[v].labelled || scene.views[v].hasPseudoLabels();
  });
  if (!supervised) {
    *out << "  warning: no labelled or pseudo-labelled view trains this block: its Gaussians' "
            "classes stay untrained (run `sadsplat pseudo-labels` on the scene, or label a view "
            "that sees it)\n";
  }
}

// The block whose decoder the merged model keeps: the most labelled views, then the most views.
int referenceBlock(const geo::BlockPartition& p, const io::Scene& scene,
                   const std::vector<int>& trained) {
  int best = trained.front();
  for (int b : trained) {
    const auto key = [&](int i) {
      return std::make_pair(p.blocks[i].labelledViews(scene), p.blocks[i].views.size());
    };
    if (key(b) > key(best)) best = b;
  }
  return best;
}

// Polls the other ranks' block directories until each has finished (torchrun stops every rank
// when one fails, so this does not outlive a failed rank).
void waitForOtherRanks(const TrainRunOptions& o, const geo::BlockPartition& partition,
                       int iterations, const BlockRunOptions& b) {
  const io::RunDirectory dir(o.out);
  bool said = false;
  for (;;) {
    std::vector<int> waiting;
    for (const geo::Block& block : partition.blocks) {
      if (block.index % b.ranks == b.rank || block.views.empty()) continue;
      if (!finished(dir.block(block.index), iterations)) waiting.push_back(block.index + 1);
    }
    if (waiting.empty()) return;
    if (!said && o.progress) {
      *o.progress << "waiting for the other ranks' " << waiting.size() << " blocks\n";
      said = true;
    }
    std::this_thread::sleep_for(std::chrono::seconds(2));
  }
}

double gib(std::int64_t bytes) { return static_cast<double>(bytes) / (1ll << 30); }

std::string gibText(std::int64_t bytes) {
  std::ostringstream text;
  text << std::setprecision(3) << gib(bytes) << " GiB";
  return text.str();
}

// The largest block estimate of a partition.
gaussians::MemoryEstimate largestBlock(const io::Scene& scene, const geo::BlockPartition& p,
                                       const gaussians::TrainConfig& config) {
  gaussians::MemoryEstimate worst;
  for (const geo::Block& block : p.blocks) {
    const gaussians::MemoryEstimate e =
        gaussians::estimateTrainingMemory(scene, block.views, block.points.size(), config);
    if (e.total() > worst.total()) worst = e;
  }
  return worst;
}

void sayEstimate(std::ostream* out, const std::string& what, const gaussians::MemoryEstimate& e) {
  if (out != nullptr) *out << what << ": " << e.describe() << "\n";
}

}  // namespace

geo::BlockPartition partitionForMemory(const io::Scene& scene, geo::BlockOptions options,
                                       const gaussians::TrainConfig& config,
                                       std::int64_t max_device_bytes, std::ostream* progress,
                                       const std::string& origin) {
  const gaussians::MemoryEstimate whole = gaussians::estimateTrainingMemory(scene, config);
  sayEstimate(progress, "the whole scene in one run", whole);
  // What no cut makes smaller: the context and one step's render of the largest view.
  gaussians::MemoryEstimate floor = whole;
  floor.views = floor.gaussians = 0;
  if (floor.total() > max_device_bytes) {
    throw Error(origin, "--max-gpu-memory",
                "at least " + gibText(floor.total()) +
                    " (one step's render of the largest view; smaller images need less)",
                gibText(max_device_bytes));
  }
  // Blocks overlap, so a block holds at least its share of what divides: start there.
  const double divisible = static_cast<double>(whole.total() - floor.total());
  const double room = static_cast<double>(max_device_bytes - floor.total());
  int blocks = std::max(options.blocks, 1);
  blocks = std::max(blocks, static_cast<int>(std::ceil(divisible / room)));
  // Blocks overlap and views see several cells, so more blocks do not always make the largest
  // smaller: up to twice the first count (at least 16 more) are tried.
  const int first = blocks, last = std::min(4096, std::max(2 * first, first + 16));
  gaussians::MemoryEstimate smallest;
  for (; blocks <= last; ++blocks) {
    options.blocks = blocks;
    geo::BlockPartition p = geo::partitionScene(scene, options, origin);
    const gaussians::MemoryEstimate worst = largestBlock(scene, p, config);
    sayEstimate(progress, std::to_string(blocks) + " blocks, the largest", worst);
    if (worst.total() <= max_device_bytes) return p;
    if (blocks == first || worst.total() < smallest.total()) smallest = worst;
  }
  std::string hint = "";
  if (!config.stream_views && smallest.views > smallest.gaussians)
    hint = "; its views are most of it: --stream-views keeps them off the device";
  throw Error(origin, "--max-gpu-memory",
              "a budget that " + std::to_string(first) + " to " + std::to_string(last) +
                  " blocks fit (the smallest largest block: " + gibText(smallest.total()) + hint +
                  ")",
              gibText(max_device_bytes));
}

BlockRun::BlockRun(TrainRunOptions options, BlockRunOptions blocks)
    : options_(std::move(options)), blocks_(std::move(blocks)) {
  if (blocks_.ranks < 1 || blocks_.rank < 0 || blocks_.rank >= blocks_.ranks)
    throw Error("<block run>", "rank", "0 .. ranks - 1", std::to_string(blocks_.rank));
  // Each block's training reads its views from a scene cache (see trainRun): the scene's pixels
  // are never all in host memory.
  scene_ = loadScene(options_.scene, options_.scale, options_.progress, ScenePixels::kLeftOnDisk);
  if (blocks_.partition.blocks == 0 && blocks_.max_device_bytes <= 0)
    throw Error("<block run>", "max_device_bytes", "a memory budget with blocks = 0 (auto)",
                std::to_string(blocks_.max_device_bytes));
  if (blocks_.max_device_bytes > 0) {
    partition_ = partitionForMemory(scene_, blocks_.partition, blocks_.budget_config,
                                    blocks_.max_device_bytes, options_.progress, options_.scene);
  } else {
    partition_ = geo::partitionScene(scene_, blocks_.partition, options_.scene);
  }
}

double BlockRun::train(const gaussians::TrainConfig& config) {
  const TrainRunOptions& o = options_;
  const BlockRunOptions& b = blocks_;
  const io::RunDirectory dir(o.out);
  if (b.rank == 0) {
    io::makeDirectory(o.out);
    io::writeTextFileAtomically(dir.blocksJson(), partition_.toJson(scene_));
  }
  const int iterations = gaussians::resolveSchedule(config, o.schedule).config.iterations;
  double seconds = 0;
  for (const geo::Block& block : partition_.blocks) {
    if (block.index % b.ranks != b.rank) continue;
    const io::RunDirectory block_dir = dir.block(block.index);
    if (block.views.empty()) {
      sayBlock(o.progress, block, partition_, scene_, "no view sees it, skipped");
      continue;
    }
    if (finished(block_dir, iterations)) {
      sayBlock(o.progress, block, partition_, scene_, "finished before, kept");
      continue;
    }
    TrainRunOptions block_options = o;
    block_options.out = block_dir.path();
    block_options.collective = nullptr;
    block_options.resume = o.resume && io::RunDirectory::hasCheckpoint(block_dir.path());
    sayBlock(o.progress, block, partition_, scene_, block_options.resume ? "resuming" : "training");
    seconds += trainRun(block_options, config, geo::blockScene(scene_, block));
  }
  if (b.rank == 0 && b.wait_for_ranks) waitForOtherRanks(o, partition_, iterations, b);
  return seconds;
}

void BlockRun::merge() const {
  const TrainRunOptions& o = options_;
  const io::RunDirectory dir(o.out);
  const std::string expected = partition_.toJson(scene_);
  if (!io::pathExists(dir.blocksJson()) || io::readWholeFile(dir.blocksJson()) != expected)
    throw Error(dir.blocksJson(), "partition",
                "the partition of this scene with these block options (train it with them)",
                io::pathExists(dir.blocksJson()) ? "another one" : "no file");
  // The blocks: each finished (its checkpoint at its configuration's iterations).
  std::vector<int> trained;
  double seconds = 0;
  for (const geo::Block& block : partition_.blocks) {
    if (block.views.empty()) continue;
    const io::RunDirectory block_dir = dir.block(block.index);
    if (!io::RunDirectory::hasCheckpoint(block_dir.path()))
      throw Error(block_dir.path(), "checkpoint.bin", "a trained block", "missing");
    const auto block_config =
        gaussians::TrainConfig::fromJson(io::readWholeFile(block_dir.config()), block_dir.config());
    const io::RunRecord record = block_dir.readRecord(false);
    if (record.iterations < block_config.iterations || !io::RunDirectory::isRun(block_dir.path()))
      throw Error(block_dir.runJson(), "iterations",
                  std::to_string(block_config.iterations) + " (a finished block)",
                  std::to_string(record.iterations));
    trained.push_back(block.index);
    seconds += record.train_seconds;
  }
  if (trained.empty()) throw Error(o.out, "blocks", "at least one trained block", "none");
  const int reference = referenceBlock(partition_, scene_, trained);
  const io::RunDirectory reference_dir = dir.block(reference);
  const gaussians::TrainConfig config = gaussians::TrainConfig::fromJson(
      io::readWholeFile(reference_dir.config()), reference_dir.config());
  // The merged model lives in a trainer over one view of the reference block: the writers
  // need a trainer, not the scene's every view on the device.
  io::Scene carrier = geo::blockScene(scene_, partition_.blocks[reference]);
  carrier.views.resize(1);
  carrier.points = scene_.points;
  gaussians::Trainer trainer(carrier, config);
  trainer.setDropStrategy(semantic_drop::makeDropStrategy(config));
  std::vector<gaussians::BlockCheckpoint> parts;
  int reference_part = 0;
  std::int64_t total = 0;
  for (int index : trained) {
    gaussians::BlockCheckpoint part;
    part.origin = dir.block(index).checkpoint();
    part.archive = gaussians::readTensorArchive(part.origin);
    const at::Tensor means = part.archive.tensor("means", part.origin).to(at::kFloat).contiguous();
    const std::vector<int> cells =
        partition_.blocksOf(means.data_ptr<float>(), static_cast<std::size_t>(means.size(0)));
    at::Tensor keep = at::empty({means.size(0)}, at::kBool);
    bool* k = keep.data_ptr<bool>();
    for (std::size_t i = 0; i < cells.size(); ++i) k[i] = cells[i] == index;
    total += means.size(0);
    if (index == reference) reference_part = static_cast<int>(parts.size());
    part.keep = keep;
    parts.push_back(std::move(part));
  }
  trainer.loadCheckpoint(
      gaussians::mergeBlockCheckpoints(parts, trainer.checkpointRowTensors(), reference_part),
      dir.checkpoint());
  io::makeDirectory(o.out);
  io::writeTextFileAtomically(dir.config(), trainer.config().toJson());
  writeTrainedRun(dir, trainer, scene_,
                  io::RunRecord{o.scene, o.scale, gaussians::choiceName(config.device),
                                trainer.iteration(), seconds},
                  o.progress);
  if (o.progress) {
    *o.progress << "merged " << trained.size() << " blocks: " << trainer.numGaussians()
                << " Gaussians (of " << total << " in the blocks, each keeping its cell's), the "
                << "decoder of block " << reference + 1 << "; " << seconds
                << " s of training in all\n";
  }
}

}  // namespace pipeline
}  // namespace sadsplat
