#include "sadsplat/gaussians/tile_list_capacity.h"

#include <algorithm>
#include <string>
#include <vector>

#include "sadsplat/common/error.h"

#if SADSPLAT_HAVE_CUDA
#include <cuda_runtime.h>
#endif

namespace sadsplat {
namespace gaussians {

namespace {
constexpr int kSlots = 64;        // counts in flight before the oldest are read early
constexpr double kShrink = 0.98;  // per check, at most
constexpr std::int64_t kSlack = 1024;

#if SADSPLAT_HAVE_CUDA
[[noreturn]] void cudaFailed(const char* what, cudaError_t err) {
  throw Error("<render>", what, "a successful CUDA call", cudaGetErrorString(err));
}
#endif
}  // namespace

struct TileListCapacity::Impl {
  double margin = 1.25;
  std::int64_t capacity = 0;
  // Counts read since the last renderedAll(): the largest, and whether one exceeded its list.
  std::int64_t largest = 0;
  bool overflowed = false;
  struct Pending {
    int slot;
    std::int64_t capacity;
  };
  std::vector<Pending> pending;
  int next_slot = 0;
#if SADSPLAT_HAVE_CUDA
  std::int64_t* counts = nullptr;  // pinned, kSlots
  std::vector<cudaEvent_t> events;
#endif

  void read(const Pending& p) {
#if SADSPLAT_HAVE_CUDA
    const cudaError_t err = cudaEventSynchronize(events[p.slot]);
    if (err != cudaSuccess) cudaFailed("cudaEventSynchronize", err);
    const std::int64_t count = counts[p.slot];
    largest = std::max(largest, count);
    if (count > p.capacity) overflowed = true;
#else
    (void)p;
#endif
  }
  void readAll() {
    for (const Pending& p : pending) read(p);
    pending.clear();
  }
  void fit(std::int64_t count) {
    capacity = std::max(static_cast<std::int64_t>(margin * static_cast<double>(count)) + kSlack,
                        static_cast<std::int64_t>(kShrink * static_cast<double>(capacity)));
  }
};

TileListCapacity::TileListCapacity(double margin) : impl_(std::make_unique<Impl>()) {
  if (!(margin >= 1)) {
    throw Error("<render>", "tile list margin", ">= 1", std::to_string(margin));
  }
  impl_->margin = margin;
}

TileListCapacity::~TileListCapacity() {
#if SADSPLAT_HAVE_CUDA
  // The counts' copies may still be queued: let them land before the memory goes.
  for (const Impl::Pending& p : impl_->pending) cudaEventSynchronize(impl_->events[p.slot]);
  for (cudaEvent_t e : impl_->events) cudaEventDestroy(e);
  if (impl_->counts != nullptr) cudaFreeHost(impl_->counts);
#endif
}

bool TileListCapacity::renderedAll() {
  Impl& s = *impl_;
  s.readAll();
  const bool all = !s.overflowed;
  if (s.largest > 0) s.fit(s.largest);
  s.largest = 0;
  s.overflowed = false;
  return all;
}

std::int64_t TileListCapacity::capacity() const { return impl_->capacity; }

TileListCapacity::Slot TileListCapacity::reserve() {
#if SADSPLAT_HAVE_CUDA
  Impl& s = *impl_;
  if (s.counts == nullptr) {
    void* memory = nullptr;
    cudaError_t err = cudaMallocHost(&memory, sizeof(std::int64_t) * kSlots);
    if (err != cudaSuccess) cudaFailed("cudaMallocHost", err);
    s.counts = static_cast<std::int64_t*>(memory);
    s.events.resize(kSlots);
    for (cudaEvent_t& e : s.events) {
      err = cudaEventCreateWithFlags(&e, cudaEventDisableTiming);
      if (err != cudaSuccess) cudaFailed("cudaEventCreate", err);
    }
  }
  // Every slot in flight: read them now (their overflow is remembered for renderedAll()).
  if (static_cast<int>(s.pending.size()) == kSlots) s.readAll();
  const int slot = s.next_slot;
  s.next_slot = (s.next_slot + 1) % kSlots;
  s.pending.push_back({slot, s.capacity});
  return {s.counts + slot, static_cast<void*>(s.events[slot])};
#else
  throw Error("<render>", "tile list capacity", "a CUDA build", "a build without CUDA");
#endif
}

void TileListCapacity::counted(std::int64_t pairs) {
  impl_->largest = std::max(impl_->largest, pairs);
  if (impl_->capacity == 0) impl_->fit(pairs);
}

}  // namespace gaussians
}  // namespace sadsplat
