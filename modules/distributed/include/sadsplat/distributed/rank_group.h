#pragma once
/// \file rank_group.h
/// \brief Data-parallel training over several processes on LibTorch's c10d: the ranks find
/// each other through a c10d::TCPStore (torchrun's variables RANK, WORLD_SIZE, MASTER_ADDR,
/// MASTER_PORT) and sum gradients with a c10d::ProcessGroupGloo (CPU tensors). Every collective
/// has a timeout, so a rank that dies stops the others with an error instead of a hang.

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
  std::string master_addr = "127.0.0.1";
  int master_port = 29500;
  /// Longest wait for a collective or the rendezvous (SADSPLAT_DIST_TIMEOUT_S, default 120 s).
  std::chrono::milliseconds timeout{120000};

  /// \brief Reads RANK, WORLD_SIZE, MASTER_ADDR, MASTER_PORT and SADSPLAT_DIST_TIMEOUT_S; empty
  /// when RANK or WORLD_SIZE is not set (a single process).
  /// \throws sadsplat::Error naming the variable when one is malformed
  static std::optional<RankEnvironment> fromProcessEnvironment();
};

/// \brief Whether this build has a process-group backend (Gloo: LibTorch with c10d + gloo's
/// headers at build time).
bool haveDistributedBackend();

/// \brief Joins the group described by `env` (rank 0 hosts the store) and returns its
/// collectives. Blocks until every rank has joined or the timeout passes.
/// \throws sadsplat::Error when the backend is missing or the rendezvous fails
gaussians::Collective::Ptr joinGroup(const RankEnvironment& env);

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
