#include "sadsplat/gaussians/cpu_threads.h"

#include <ATen/Parallel.h>

#include <cstdlib>
#include <thread>

namespace sadsplat {
namespace gaussians {

int setCpuThreads(int threads) {
  if (threads <= 0) {
    const char* env = std::getenv("OMP_NUM_THREADS");
    threads = env != nullptr ? std::atoi(env) : 0;
  }
  if (threads <= 0) threads = static_cast<int>(std::thread::hardware_concurrency());
  if (threads > 0 && threads != at::get_num_threads()) at::set_num_threads(threads);
  return at::get_num_threads();
}

}  // namespace gaussians
}  // namespace sadsplat
