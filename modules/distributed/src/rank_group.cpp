#include "sadsplat/distributed/rank_group.h"

#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <thread>

#if SADSPLAT_HAVE_GLOO
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#endif
#if SADSPLAT_HAVE_NCCL
#include <c10/cuda/CUDAFunctions.h>
#include <torch/csrc/distributed/c10d/ProcessGroupNCCL.hpp>
#endif
#if SADSPLAT_HAVE_GLOO || SADSPLAT_HAVE_NCCL
#include <torch/csrc/distributed/c10d/TCPStore.hpp>
#endif
#include <sstream>

#include "sadsplat/common/error.h"

extern char** environ;

namespace sadsplat {
namespace distributed {
namespace {

int readInt(const char* name, const char* text, int low, int high) {
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0' || value < low || value > high) {
    throw Error(std::string("environment variable ") + name, "value",
                "an integer in [" + std::to_string(low) + ", " + std::to_string(high) + "]", text);
  }
  return static_cast<int>(value);
}

// A port the kernel reports free right now (bind to port 0).
int freePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0)
    throw Error("<distributed>", "socket", "a TCP socket for the rendezvous port",
                std::strerror(errno));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof addr;
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0;
  ::close(fd);
  if (!ok)
    throw Error("<distributed>", "rendezvous port", "a free port on 127.0.0.1",
                std::strerror(errno));
  return ntohs(addr.sin_port);
}

#if SADSPLAT_HAVE_GLOO || SADSPLAT_HAVE_NCCL
std::string where(const RankEnvironment& env) {
  return "rank " + std::to_string(env.rank) + " of " + std::to_string(env.world_size);
}
std::string firstLine(const std::string& text) { return text.substr(0, text.find('\n')); }

// The rendezvous: rank 0 hosts a c10d::TCPStore at MASTER_ADDR:MASTER_PORT, the others connect.
c10::intrusive_ptr<c10d::Store> connectStore(const RankEnvironment& env) {
  c10d::TCPStoreOptions store_options;
  store_options.port = static_cast<std::uint16_t>(env.master_port);
  // Under torchrun the agent already hosts the store at MASTER_PORT: every rank is a client.
  const char* agent_store = std::getenv("TORCHELASTIC_USE_AGENT_STORE");
  store_options.isServer =
      env.rank == 0 && !(agent_store != nullptr && std::string(agent_store) == "True");
  store_options.numWorkers = static_cast<std::size_t>(env.world_size);
  store_options.waitWorkers = true;
  store_options.timeout = env.timeout;
  return c10::make_intrusive<c10d::TCPStore>(env.master_addr, store_options);
}

Error rendezvousError(const RankEnvironment& env, const std::string& what) {
  return Error(where(env),
               "rendezvous at " + env.master_addr + ":" + std::to_string(env.master_port),
               "all " + std::to_string(env.world_size) + " ranks within " +
                   std::to_string(env.timeout.count() / 1000) + " s",
               firstLine(what));
}

// Sums and maxima through one c10d process group (Gloo: 1.13's ProcessGroup; NCCL: 2.x's
// Backend; both have the same allreduce). `kHostOnly`: the backend reduces CPU tensors only, so
// a CUDA tensor goes through the host.
template <class Group, bool kHostOnly>
class ProcessGroupCollective : public gaussians::Collective {
 public:
  ProcessGroupCollective(const RankEnvironment& env, c10::intrusive_ptr<Group> group)
      : env_(env), group_(std::move(group)) {}
  // No explicit shutdown(): LibTorch 2.11's NCCL shutdown at the end of a run blocked rank 1 while
  // rank 0 waited for it to exit (the group's destructor ends it; NCCL warns that
  // destroy_process_group() was not called, which is harmless here).
  int rank() const override { return env_.rank; }
  int size() const override { return env_.world_size; }
  void sum(at::Tensor& tensor) override { reduce(tensor, c10d::ReduceOp::SUM); }
  void max(at::Tensor& tensor) override { reduce(tensor, c10d::ReduceOp::MAX); }

 private:
  void reduce(at::Tensor& tensor, c10d::ReduceOp::RedOpType op) {
    const bool via_host = kHostOnly && tensor.is_cuda();
    at::Tensor data = via_host ? tensor.cpu() : tensor.contiguous();
    std::vector<at::Tensor> tensors{data};
    c10d::AllreduceOptions options;
    options.reduceOp = c10d::ReduceOp(op);
    try {
      group_->allreduce(tensors, options)->wait();
    } catch (const std::exception& e) {  // c10::Error, or gloo's own IoException
      throw Error(where(env_), "all-reduce",
                  "every rank to answer within " + std::to_string(env_.timeout.count() / 1000) +
                      " s (another rank stopped or died)",
                  firstLine(e.what()));
    }
    if (via_host || !data.is_same(tensor)) tensor.copy_(data);
  }

  RankEnvironment env_;
  c10::intrusive_ptr<Group> group_;
};
#endif

#if SADSPLAT_HAVE_GLOO
gaussians::Collective::Ptr joinGloo(const RankEnvironment& env) {
  try {
    auto store = connectStore(env);
    auto options = c10d::ProcessGroupGloo::Options::create();
    options->timeout = env.timeout;
    options->devices.push_back(c10d::ProcessGroupGloo::createDeviceForHostname(env.master_addr));
    auto group =
        c10::make_intrusive<c10d::ProcessGroupGloo>(store, env.rank, env.world_size, options);
    return std::make_shared<ProcessGroupCollective<c10d::ProcessGroupGloo, true>>(env, group);
  } catch (const c10::Error& e) {
    throw rendezvousError(env, e.what());
  }
}
#endif

#if SADSPLAT_HAVE_NCCL
gaussians::Collective::Ptr joinNccl(const RankEnvironment& env) {
  // bindLocalGpu left this rank exactly one GPU, its cuda:0.
  if (c10::cuda::device_count() < 1) {
    const char* visible = std::getenv("CUDA_VISIBLE_DEVICES");
    throw Error(where(env), "GPU",
                "one GPU per rank (local rank " + std::to_string(env.local_rank) + " uses GPU " +
                    std::to_string(env.local_rank) + ")",
                std::string("none visible, CUDA_VISIBLE_DEVICES=") +
                    (visible != nullptr ? visible : "(unset)"));
  }
  try {
    auto store = connectStore(env);
    auto options = c10d::ProcessGroupNCCL::Options::create();
    // A collective that waits longer ends the process (NCCL's watchdog), not a hang.
    options->timeout = env.timeout;
    auto group =
        c10::make_intrusive<c10d::ProcessGroupNCCL>(store, env.rank, env.world_size, options);
    return std::make_shared<ProcessGroupCollective<c10d::ProcessGroupNCCL, false>>(env, group);
  } catch (const c10::Error& e) {
    throw rendezvousError(env, e.what());
  }
}
#endif

}  // namespace

std::optional<RankEnvironment> RankEnvironment::fromProcessEnvironment() {
  const char* rank = std::getenv("RANK");
  const char* world = std::getenv("WORLD_SIZE");
  if (rank == nullptr || world == nullptr) return std::nullopt;
  RankEnvironment env;
  env.world_size = readInt("WORLD_SIZE", world, 1, 4096);
  env.rank = readInt("RANK", rank, 0, env.world_size - 1);
  env.local_rank = env.rank;
  if (const char* local = std::getenv("LOCAL_RANK")) {
    env.local_rank = readInt("LOCAL_RANK", local, 0, env.world_size - 1);
  }
  if (const char* addr = std::getenv("MASTER_ADDR")) env.master_addr = addr;
  if (const char* port = std::getenv("MASTER_PORT")) {
    env.master_port = readInt("MASTER_PORT", port, 1, 65535);
  }
  if (const char* timeout = std::getenv("SADSPLAT_DIST_TIMEOUT_S")) {
    env.timeout =
        std::chrono::milliseconds(1000LL * readInt("SADSPLAT_DIST_TIMEOUT_S", timeout, 1, 86400));
  }
  return env;
}

bool haveDistributedBackend(const std::string& device) {
  const bool cuda = device.rfind("cuda", 0) == 0;
  return cuda ? SADSPLAT_HAVE_NCCL != 0 : SADSPLAT_HAVE_GLOO != 0;
}

void bindLocalGpu(const RankEnvironment& env) {
  const std::string rank = "rank " + std::to_string(env.rank);
  const char* visible = std::getenv("CUDA_VISIBLE_DEVICES");
  std::string gpu = std::to_string(env.local_rank);
  if (visible != nullptr && *visible != '\0') {
    std::vector<std::string> listed;
    std::stringstream list(visible);
    for (std::string id; std::getline(list, id, ',');) listed.push_back(id);
    if (env.local_rank >= static_cast<int>(listed.size())) {
      throw Error(rank, "CUDA_VISIBLE_DEVICES",
                  "one GPU per local rank (at least " + std::to_string(env.local_rank + 1) + ")",
                  visible);
    }
    gpu = listed[env.local_rank];
  }
  ::setenv("CUDA_VISIBLE_DEVICES", gpu.c_str(), 1);
}

gaussians::Collective::Ptr joinGroup(const RankEnvironment& env, const std::string& device) {
  const bool cuda = device.rfind("cuda", 0) == 0;
#if SADSPLAT_HAVE_NCCL
  if (cuda) return joinNccl(env);
#endif
#if SADSPLAT_HAVE_GLOO
  if (!cuda) return joinGloo(env);
#endif
  throw Error("rank " + std::to_string(env.rank), "distributed backend",
              cuda ? "a CUDA build with c10d NCCL (LibTorch built with USE_C10D_NCCL and nccl.h)"
                   : "a build with c10d Gloo (LibTorch with distributed support and gloo's "
                     "headers, Debian: libgloo-dev)",
              std::string("none for --device ") + device + " in this build");
}

LocalRanks::LocalRanks(int nproc, const std::vector<std::string>& args) {
  if (nproc < 1) throw Error("--nproc", "value", ">= 1", std::to_string(nproc));
  const std::string port =
      std::getenv("MASTER_PORT") ? std::getenv("MASTER_PORT") : std::to_string(freePort());
  ::setenv("WORLD_SIZE", std::to_string(nproc).c_str(), 1);
  ::setenv("MASTER_ADDR", "127.0.0.1", 1);
  ::setenv("MASTER_PORT", port.c_str(), 1);
  ::setenv("RANK", "0", 1);
  ::setenv("LOCAL_RANK", "0", 1);
  // The ranks share the cores (unless OMP_NUM_THREADS says otherwise).
  if (std::getenv("OMP_NUM_THREADS") == nullptr) {
    const int cores = static_cast<int>(std::thread::hardware_concurrency());
    ::setenv("OMP_NUM_THREADS", std::to_string(std::max(1, cores / nproc)).c_str(), 1);
  }
  std::vector<std::string> argv_text = {"/proc/self/exe"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (int r = 1; r < nproc; ++r) {
    ::setenv("RANK", std::to_string(r).c_str(), 1);
    ::setenv("LOCAL_RANK", std::to_string(r).c_str(), 1);
    pid_t pid = 0;
    const int rc = ::posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ);
    ::setenv("RANK", "0", 1);
    ::setenv("LOCAL_RANK", "0", 1);
    if (rc != 0) {
      throw Error("rank " + std::to_string(r), "process", "started", std::strerror(rc));
    }
    pids_.push_back(pid);
  }
}

LocalRanks::~LocalRanks() {
  for (int pid : pids_) ::kill(pid, SIGTERM);
  for (int pid : pids_) ::waitpid(pid, nullptr, 0);
}

void LocalRanks::waitAll() {
  std::vector<int> pids;
  pids.swap(pids_);
  std::string failure;
  for (std::size_t k = 0; k < pids.size(); ++k) {
    int status = 0;
    ::waitpid(pids[k], &status, 0);
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (!ok && failure.empty()) {
      failure = "rank " + std::to_string(k + 1) +
                (WIFEXITED(status) ? " exited with status " + std::to_string(WEXITSTATUS(status))
                                   : " was killed by signal " + std::to_string(WTERMSIG(status)));
    }
  }
  if (!failure.empty()) throw Error("<distributed>", "ranks", "every rank to succeed", failure);
}

}  // namespace distributed
}  // namespace sadsplat
