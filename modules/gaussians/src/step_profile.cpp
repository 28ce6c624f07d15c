#include "sadsplat/gaussians/step_profile.h"

#include <ATen/record_function.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <mutex>
#include <numeric>

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDACachingAllocator.h>
#include <c10/cuda/CUDAFunctions.h>
#endif

namespace sadsplat {
namespace gaussians {
namespace {

std::atomic<StepProfile*> g_active{nullptr};

// ATen operator calls of the whole process while at least one profile exists: one RecordFunction
// callback (for every thread), added by the first profile and removed with the last.
std::atomic<std::int64_t> g_operator_calls{0};
std::mutex g_counter_mutex;
int g_counting_profiles = 0;
at::CallbackHandle g_counter_handle = 0;

}  // namespace

struct OperatorCallObserver {
  static std::unique_ptr<at::ObserverContext> onCall(const at::RecordFunction& fn) {
    g_operator_calls.fetch_add(1, std::memory_order_relaxed);
    if (StepProfile* profile = g_active.load()) profile->recordOperator(fn.name());
    return nullptr;
  }
};

namespace {

void startCountingOperatorCalls() {
  const std::lock_guard<std::mutex> lock(g_counter_mutex);
  if (g_counting_profiles++ == 0) {
    g_counter_handle =
        at::addGlobalCallback(at::RecordFunctionCallback(OperatorCallObserver::onCall)
                                  .scopes({at::RecordScope::FUNCTION}));
  }
}

void stopCountingOperatorCalls() {
  const std::lock_guard<std::mutex> lock(g_counter_mutex);
  if (--g_counting_profiles == 0) at::removeCallback(g_counter_handle);
}

struct DevicePeaks {
  std::int64_t allocated = 0;
  std::int64_t reserved = 0;
};

// The caching allocator's peaks since the last resetDevicePeaks() (index 0 of its stat arrays is
// the aggregate over pool kinds).
DevicePeaks devicePeaks(const at::Device& device) {
#if SADSPLAT_HAVE_CUDA
  if (device.is_cuda()) {
    const auto stats =
        c10::cuda::CUDACachingAllocator::getDeviceStats(device.has_index() ? device.index() : 0);
    return {stats.allocated_bytes[0].peak, stats.reserved_bytes[0].peak};
  }
#else
  (void)device;
#endif
  return {};
}

void resetDevicePeaks(const at::Device& device) {
#if SADSPLAT_HAVE_CUDA
  if (device.is_cuda()) {
    c10::cuda::CUDACachingAllocator::resetPeakStats(device.has_index() ? device.index() : 0);
  }
#else
  (void)device;
#endif
}

}  // namespace

void synchronizeDevice(const at::Device& device) {
#if SADSPLAT_HAVE_CUDA
  if (device.is_cuda()) c10::cuda::device_synchronize();
#else
  (void)device;
#endif
}

StepProfile* activeProfile() { return g_active.load(); }
void setActiveProfile(StepProfile* profile) { g_active.store(profile); }

StepProfile::StepProfile(const at::Device& device, Clock clock) : device_(device), clock_(clock) {
  const DevicePeaks before = devicePeaks(device_);
  peak_allocated_before_ = before.allocated;
  peak_reserved_before_ = before.reserved;
  startCountingOperatorCalls();
}

StepProfile::~StepProfile() { stopCountingOperatorCalls(); }

const StepProfile::Phase* StepProfile::find(const std::string& name) const {
  const auto it =
      std::find_if(phases_.begin(), phases_.end(), [&](const Phase& p) { return p.name == name; });
  return it == phases_.end() ? nullptr : &*it;
}

int StepProfile::indexOf(const std::string& name) {
  if (const Phase* p = find(name)) return static_cast<int>(p - phases_.data());
  phases_.push_back(Phase{name});
  return static_cast<int>(phases_.size()) - 1;
}

bool StepProfile::waitsForDevice() const { return clock_ == Clock::kDeviceWaited; }

void StepProfile::closeSlice() {
  if (waitsForDevice()) synchronizeDevice(device_);
  const auto now = std::chrono::steady_clock::now();
  if (stack_.empty()) return;
  Phase& p = phases_[static_cast<std::size_t>(stack_.back())];
  p.seconds += std::chrono::duration<double>(now - start_).count();
  p.operator_calls += g_operator_calls.load() - calls_at_open_;
  if (!waitsForDevice()) return;  // peaks read while the device runs would mean little
  const DevicePeaks peaks = devicePeaks(device_);
  p.peak_allocated = std::max(p.peak_allocated, peaks.allocated);
  peak_reserved_ = std::max(peak_reserved_, peaks.reserved);
}

void StepProfile::openSlice() {
  open_phase_.store(stack_.empty() ? -1 : stack_.back());
  if (waitsForDevice()) resetDevicePeaks(device_);
  calls_at_open_ = g_operator_calls.load();
  start_ = std::chrono::steady_clock::now();  // closeSlice() has synchronised the device
}

void StepProfile::enter(const std::string& name) {
  leave();
  push(name);
}

void StepProfile::leave() {
  closeSlice();
  stack_.clear();
  open_phase_.store(-1);
}

void StepProfile::push(const std::string& name) {
  closeSlice();
  const std::string full =
      stack_.empty() ? name : phases_[static_cast<std::size_t>(stack_.back())].name + " / " + name;
  stack_.push_back(indexOf(full));
  openSlice();
}

void StepProfile::pop() {
  closeSlice();
  if (!stack_.empty()) stack_.pop_back();
  if (!stack_.empty()) {
    openSlice();
  } else {
    open_phase_.store(-1);
  }
}

void StepProfile::recordOperator(const char* name) {
  const int phase = open_phase_.load();
  if (phase < 0 || name == nullptr) return;
  const std::lock_guard<std::mutex> lock(names_mutex_);
  if (operator_names_.size() <= static_cast<std::size_t>(phase)) {
    operator_names_.resize(static_cast<std::size_t>(phase) + 1);
  }
  ++operator_names_[static_cast<std::size_t>(phase)][name];
}

std::string StepProfile::operatorTable(double min_per_iteration) const {
  const std::lock_guard<std::mutex> lock(names_mutex_);
  const double iterations = std::max(1, iterations_);
  std::string out;
  char line[512];
  for (std::size_t k = 0; k < operator_names_.size() && k < phases_.size(); ++k) {
    std::vector<std::pair<std::int64_t, std::string>> calls;
    std::int64_t total = 0;
    for (const auto& [name, count] : operator_names_[k]) {
      calls.emplace_back(count, name);
      total += count;
    }
    if (calls.empty()) continue;
    std::sort(calls.begin(), calls.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    std::snprintf(line, sizeof line, "\n**%s**: %.1f calls per iteration\n\n",
                  phases_[k].name.c_str(), total / iterations);
    out += line;
    for (const auto& [count, name] : calls) {
      if (count / iterations < min_per_iteration) break;
      std::snprintf(line, sizeof line, "- %.2f `%s`\n", count / iterations, name.c_str());
      out += line;
    }
  }
  return out;
}

double StepProfile::seconds(const std::string& name) const {
  const Phase* p = find(name);
  return p == nullptr ? 0.0 : p->seconds;
}

std::int64_t StepProfile::peakAllocatedBytes(const std::string& name) const {
  const Phase* p = find(name);
  return p == nullptr ? 0 : p->peak_allocated;
}

std::int64_t StepProfile::operatorCalls(const std::string& name) const {
  const Phase* p = find(name);
  return p == nullptr ? 0 : p->operator_calls;
}

double StepProfile::totalSeconds() const {
  return std::accumulate(phases_.begin(), phases_.end(), 0.0,
                         [](double sum, const Phase& p) { return sum + p.seconds; });
}

std::string StepProfile::table() const {
  const double total = totalSeconds();
  const double per = 1000.0 / std::max(1, iterations_);
  const bool memory = device_.is_cuda() && waitsForDevice();
  constexpr double kMiB = 1024.0 * 1024.0;
  std::string out =
      memory ? "| phase | total s | ms / iteration | share | operator calls / iteration | peak "
               "allocated MiB |\n|---|---|---|---|---|---|\n"
             : "| phase | total s | ms / iteration | share | operator calls / iteration |\n"
               "|---|---|---|---|---|\n";
  char line[512];
  std::int64_t peak = 0, calls = 0;
  for (const Phase& p : phases_) {
    std::snprintf(line, sizeof line, "| %s | %.3f | %.3f | %.1f %% | %.1f |", p.name.c_str(),
                  p.seconds, p.seconds * per, total > 0 ? 100.0 * p.seconds / total : 0.0,
                  static_cast<double>(p.operator_calls) / std::max(1, iterations_));
    calls += p.operator_calls;
    out += line;
    if (memory) {
      std::snprintf(line, sizeof line, " %.0f |", p.peak_allocated / kMiB);
      out += line;
    }
    out += "\n";
    peak = std::max(peak, p.peak_allocated);
  }
  std::snprintf(line, sizeof line,
                "| **total** (%d iterations) | %.3f | %.3f | 100 %% | %.1f |%s\n", iterations_,
                total, total * per, static_cast<double>(calls) / std::max(1, iterations_),
                memory ? " |" : "");
  out += line;
  if (memory) {
    std::snprintf(line, sizeof line,
                  "\nDevice memory over the profiled phases: peak allocated %.0f MiB, peak "
                  "reserved by the caching allocator %.0f MiB; before the first phase (scene "
                  "loading, initialisation): %.0f MiB allocated, %.0f MiB reserved.\n",
                  peak / kMiB, peak_reserved_ / kMiB, peak_allocated_before_ / kMiB,
                  peak_reserved_before_ / kMiB);
    out += line;
  }
  return out;
}

}  // namespace gaussians
}  // namespace sadsplat
