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
#include <torch/csrc/distributed/c10d/TCPStore.hpp>
#endif

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
  if (fd < 0) throw Error("<distributed>", "socket", "a TCP socket for the rendezvous port");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof addr;
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0;
  ::close(fd);
  if (!ok) throw Error("<distributed>", "rendezvous port", "a free port on 127.0.0.1");
  return ntohs(addr.sin_port);
}

#if SADSPLAT_HAVE_GLOO
class GlooCollective : public gaussians::Collective {
 public:
  GlooCollective(const RankEnvironment& env) : env_(env) {
    try {
      c10d::TCPStoreOptions store_options;
      store_options.port = static_cast<std::uint16_t>(env.master_port);
      // Under torchrun the agent already hosts the store at MASTER_PORT: every rank is a client.
      const char* agent_store = std::getenv("TORCHELASTIC_USE_AGENT_STORE");
      store_options.isServer =
          env.rank == 0 && !(agent_store != nullptr && std::string(agent_store) == "True");
      store_options.numWorkers = static_cast<std::size_t>(env.world_size);
      store_options.waitWorkers = true;
      store_options.timeout = env.timeout;
      auto store = c10::make_intrusive<c10d::TCPStore>(env.master_addr, store_options);
      auto options = c10d::ProcessGroupGloo::Options::create();
      options->timeout = env.timeout;
      options->devices.push_back(c10d::ProcessGroupGloo::createDeviceForHostname(env.master_addr));
      group_ =
          c10::make_intrusive<c10d::ProcessGroupGloo>(store, env.rank, env.world_size, options);
    } catch (const c10::Error& e) {
      throw Error(where(),
                  "rendezvous at " + env.master_addr + ":" + std::to_string(env.master_port),
                  "all " + std::to_string(env.world_size) + " ranks within " +
                      std::to_string(env.timeout.count() / 1000) + " s",
                  firstLine(e.what()));
    }
  }
  int rank() const override { return env_.rank; }
  int size() const override { return env_.world_size; }
  void sum(at::Tensor& tensor) override { reduce(tensor, c10d::ReduceOp::SUM); }
  void max(at::Tensor& tensor) override { reduce(tensor, c10d::ReduceOp::MAX); }

 private:
  std::string where() const {
    return "rank " + std::to_string(env_.rank) + " of " + std::to_string(env_.world_size);
  }
  static std::string firstLine(const std::string& text) { return text.substr(0, text.find('\n')); }

  void reduce(at::Tensor& tensor, c10d::ReduceOp::RedOpType op) {
    // Gloo reduces CPU tensors; a CUDA tensor goes through the host.
    at::Tensor host = tensor.is_cuda() ? tensor.cpu() : tensor.contiguous();
    std::vector<at::Tensor> tensors{host};
    c10d::AllreduceOptions options;
    options.reduceOp = c10d::ReduceOp(op);
    try {
      group_->allreduce(tensors, options)->wait();
    } catch (const std::exception& e) {  // c10::Error, or gloo's own IoException
      throw Error(where(), "all-reduce",
                  "every rank to answer within " + std::to_string(env_.timeout.count() / 1000) +
                      " s (another rank stopped or died)",
                  firstLine(e.what()));
    }
    if (tensor.is_cuda() || !host.is_same(tensor)) tensor.copy_(host);
  }

  RankEnvironment env_;
  c10::intrusive_ptr<c10d::ProcessGroupGloo> group_;
};
#endif

}  // namespace

std::optional<RankEnvironment> RankEnvironment::fromProcessEnvironment() {
  const char* rank = std::getenv("RANK");
  const char* world = std::getenv("WORLD_SIZE");
  if (rank == nullptr || world == nullptr) return std::nullopt;
  RankEnvironment env;
  env.world_size = readInt("WORLD_SIZE", world, 1, 4096);
  env.rank = readInt("RANK", rank, 0, env.world_size - 1);
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

bool haveDistributedBackend() { return SADSPLAT_HAVE_GLOO != 0; }

gaussians::Collective::Ptr joinGroup(const RankEnvironment& env) {
#if SADSPLAT_HAVE_GLOO
  return std::make_shared<GlooCollective>(env);
#else
  throw Error("rank " + std::to_string(env.rank), "distributed backend",
              "a build with c10d Gloo (LibTorch with distributed support and gloo's headers, "
              "Debian: libgloo-dev)",
              "none in this build");
#endif
}

LocalRanks::LocalRanks(int nproc, const std::vector<std::string>& args) {
  if (nproc < 1) throw Error("--nproc", "value", ">= 1", std::to_string(nproc));
  const std::string port =
      std::getenv("MASTER_PORT") ? std::getenv("MASTER_PORT") : std::to_string(freePort());
  ::setenv("WORLD_SIZE", std::to_string(nproc).c_str(), 1);
  ::setenv("MASTER_ADDR", "127.0.0.1", 1);
  ::setenv("MASTER_PORT", port.c_str(), 1);
  ::setenv("RANK", "0", 1);
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
    pid_t pid = 0;
    const int rc = ::posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ);
    ::setenv("RANK", "0", 1);
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
