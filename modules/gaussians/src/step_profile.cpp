#include "sadsplat/gaussians/step_profile.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAFunctions.h>
#endif

namespace sadsplat {
namespace gaussians {

void synchronizeDevice(const at::Device& device) {
#if SADSPLAT_HAVE_CUDA
  if (device.is_cuda()) c10::cuda::device_synchronize();
#else
  (void)device;
#endif
}

StepProfile::StepProfile(const at::Device& device) : device_(device) {}

void StepProfile::enter(const std::string& name) {
  leave();
  const auto it = std::find(names_.begin(), names_.end(), name);
  current_ = static_cast<int>(it - names_.begin());
  if (it == names_.end()) {
    names_.push_back(name);
    seconds_.push_back(0.0);
  }
  start_ = std::chrono::steady_clock::now();  // leave() has synchronised the device
}

void StepProfile::leave() {
  synchronizeDevice(device_);
  const auto now = std::chrono::steady_clock::now();
  if (current_ >= 0) {
    seconds_[static_cast<std::size_t>(current_)] +=
        std::chrono::duration<double>(now - start_).count();
  }
  current_ = -1;
}

double StepProfile::seconds(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  return it == names_.end() ? 0.0 : seconds_[static_cast<std::size_t>(it - names_.begin())];
}

double StepProfile::totalSeconds() const {
  return std::accumulate(seconds_.begin(), seconds_.end(), 0.0);
}

std::string StepProfile::table() const {
  const double total = totalSeconds();
  const double per = 1000.0 / std::max(1, iterations_);
  std::string out = "| phase | total s | ms / iteration | share |\n|---|---|---|---|\n";
  char line[256];
  for (std::size_t k = 0; k < names_.size(); ++k) {
    std::snprintf(line, sizeof line, "| %s | %.3f | %.3f | %.1f %% |\n", names_[k].c_str(),
                  seconds_[k], seconds_[k] * per, total > 0 ? 100.0 * seconds_[k] / total : 0.0);
    out += line;
  }
  std::snprintf(line, sizeof line, "| **total** (%d iterations) | %.3f | %.3f | 100 %% |\n",
                iterations_, total, total * per);
  return out + line;
}

}  // namespace gaussians
}  // namespace sadsplat
