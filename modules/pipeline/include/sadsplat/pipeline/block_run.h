#pragma once
/// \file block_run.h
/// \brief `sadsplat train --blocks N`: a scene trained block by block (geo/block_partition.h:
/// cells on the ground plane, grown by an overlap, each with the views that see it) and merged
/// into one run (gaussians/block_merge.h), so that `eval`, `render`, `ortho` and `extract` read
/// it as any other run. Each block is an ordinary run directory under RUN/blocks/; blocks are
/// trained one after another, or shared among ranks (each process trains its own blocks: no
/// collective, nothing to wait for until the merge).

#include <ostream>
#include <string>

#include "sadsplat/geo/block_partition.h"
#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/pipeline/train_run.h"

namespace sadsplat {
namespace pipeline {

/// \brief How a block run is cut and shared.
struct BlockRunOptions {
  geo::BlockOptions partition;
  int rank = 0;   ///< this process trains blocks rank, rank + ranks, rank + 2 ranks, ...
  int ranks = 1;  ///< processes sharing the blocks
  /// Rank 0 waits, after its own blocks, until the other ranks' blocks have finished (ranks
  /// started by torchrun; ranks this process started are waited for as processes instead).
  bool wait_for_ranks = false;
  /// When > 0 (`--max-gpu-memory`): the fewest blocks, at least partition.blocks (0 = auto),
  /// whose every block's estimated peak device memory (gaussians/memory_estimate.h) for
  /// `budget_config` is at most this many bytes.
  std::int64_t max_device_bytes = 0;
  gaussians::TrainConfig budget_config;
};

/// \brief The partition with the fewest blocks whose every block's estimated training memory
/// with `config` fits `max_device_bytes`: from options.blocks or the share that must divide
/// (whichever is larger) up to twice that count (at least 16 more); says each try on `progress`.
/// \throws sadsplat::Error naming `origin` when one step's render alone does not fit, or no
/// count tried fits (with a hint to --stream-views when the views are most of it)
geo::BlockPartition partitionForMemory(const io::Scene& scene, geo::BlockOptions options,
                                       const gaussians::TrainConfig& config,
                                       std::int64_t max_device_bytes, std::ostream* progress,
                                       const std::string& origin);

/// \brief A scene (options.scene, loaded once) and its partition, trained block by block into
/// options.out.
class BlockRun {
 public:
  /// \throws sadsplat::Error on a scene that cannot be read or partitioned
  BlockRun(TrainRunOptions options, BlockRunOptions blocks);

  const io::Scene& scene() const { return scene_; }
  const geo::BlockPartition& partition() const { return partition_; }

  /// \brief Writes RUN/blocks.json (rank 0) and trains this rank's blocks into RUN/blocks/bNNN,
  /// each on its views and the sparse points of its grown cell, with `config` (each block gets
  /// the whole schedule). A block that finished is kept; with options.resume an interrupted one
  /// continues from its checkpoint. A block no view sees is skipped. Returns the seconds this
  /// rank trained.
  /// \throws sadsplat::Error on bad input or a failed block (naming its directory)
  double train(const gaussians::TrainConfig& config);

  /// \brief Merges the finished blocks of RUN into RUN itself (checkpoint.bin, model.ply,
  /// run.json, config.json, ...): each block's Gaussians whose centre lies in its cell, the
  /// decoders made one (the decoder of the block with the most labelled views). run.json's
  /// train_seconds is the blocks' sum (one device's time).
  /// \throws sadsplat::Error when blocks.json is not this partition (trained with other block
  /// options), or a block that has views has not finished
  void merge() const;

 private:
  TrainRunOptions options_;
  BlockRunOptions blocks_;
  io::Scene scene_;
  geo::BlockPartition partition_;
};

}  // namespace pipeline
}  // namespace sadsplat
