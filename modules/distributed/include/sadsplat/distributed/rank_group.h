#pragma once
/// \file rank_group.h
/// \brief Data-parallel training over several processes on LibTorch's c10d: the ranks find
/// each other through a c10d::TCPStore (torchrun's variables RANK, WORLD_SIZE, LOCAL_RANK,
/// MASTER_ADDR, MASTER_PORT) and sum gradients with a c10d::ProcessGroupGloo (CPU training) or a
/// c10d::ProcessGroupNCCL (CUDA training, one GPU per rank). Every collective has a timeout, so a
/// rank that dies stops the others with an error instead of a hang.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sadsplat/gaussians/collective.h"

namespace sadsplat {
namespace distributed {

/// \brief Where this process stands in a group (torchrun's environment variables).
struct RankEnvironment {
  int rank = 0;
  int world_size = 1;
  /// The rank on this host (LOCAL_RANK, default: rank): which GPU a CUDA rank uses.
  int local_rank = 0;
  std::string master_addr = "127.0.0.1";
  int master_port = 29500;
  /// Longest wait for a collective or the rendezvous (SADSPLAT_DIST_TIMEOUT_S, default 120 s).
  std::chrono::milliseconds timeout{120000};

  /// \brief Reads RANK, WORLD_SIZE, MASTER_ADDR, MASTER_PORT and SADSPLAT_DIST_TIMEOUT_S; empty
  /// when RANK or WORLD_SIZE is not set (a single process).
  /// \throws sadsplat::Error naming the variable when one is malformed
  static std::optional<RankEnvironment> fromProcessEnvironment();
};

/// \brief Whether this build can train on `device` ("cpu": c10d Gloo, LibTorch with gloo's headers
/// at build time; "cuda": c10d NCCL, a CUDA LibTorch built with it).
bool haveDistributedBackend(const std::string& device);

/// \brief Gives this rank its own GPU: narrows CUDA_VISIBLE_DEVICES to the local rank's entry
/// (or sets it to the local rank), so that the rank's "cuda" is that GPU. Call it before anything
/// touches CUDA.
/// \throws sadsplat::Error when CUDA_VISIBLE_DEVICES lists fewer GPUs than local ranks
void bindLocalGpu(const RankEnvironment& env);

/// \brief Joins the group described by `env` (rank 0 hosts the store) and returns its
/// collectives: NCCL when `device` is "cuda", Gloo for "cpu". Blocks until every rank has joined
/// or the timeout passes.
/// \throws sadsplat::Error when the backend is missing or the rendezvous fails
gaussians::Collective::Ptr joinGroup(const RankEnvironment& env, const std::string& device);

/// \brief Ranks 1 .. nproc-1 of a local group, started as copies of this program.
class LocalRanks {
 public:
  /// \brief Sets this process's own RANK=0 / WORLD_SIZE / MASTER_ADDR=127.0.0.1 / MASTER_PORT (a
  /// free port) and starts `nproc - 1` copies of /proc/self/exe with `args` (argv without the
  /// program name) and RANK = 1 .. nproc-1. Without OMP_NUM_THREADS, each rank gets cores / nproc
  /// CPU threads.
  /// \throws sadsplat::Error when a process cannot be started
  LocalRanks(int nproc, const std::vector<std::string>& args);
  /// \brief Stops (SIGTERM) and reaps the ranks still running.
  ~LocalRanks();
  LocalRanks(const LocalRanks&) = delete;
  LocalRanks& operator=(const LocalRanks&) = delete;

  /// \brief Waits for every started rank.
  /// \throws sadsplat::Error naming the first rank that failed and its exit status
  void waitAll();

 private:
  std::vector<int> pids_;
};

}  // namespace distributed
}  // namespace sadsplat
