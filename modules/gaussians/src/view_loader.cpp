#include "view_loader.h"

#include <algorithm>

namespace sadsplat {
namespace gaussians {

ViewLoader::ViewLoader(Load load, int threads) : load_(std::move(load)) {
  for (int i = 0; i < std::max(1, threads); ++i) threads_.emplace_back([this] { work(); });
}

ViewLoader::~ViewLoader() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    queue_.clear();  // their futures report a broken promise, and nobody waits for them
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void ViewLoader::work() {
  for (;;) {
    std::packaged_task<HostView()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task();  // an exception is stored in the future, for take to rethrow
  }
}

void ViewLoader::request(int view, int step) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto found = entries_.find(view);
    if (found != entries_.end()) {
      found->second.last_step = std::max(found->second.last_step, step);
      return;
    }
    std::packaged_task<HostView()> task([this, view] { return load_(view); });
    entries_[view] = Entry{task.get_future().share(), step};
    queue_.push_back(std::move(task));
  }
  wake_.notify_one();
}

HostView ViewLoader::take(int view) {
  std::shared_future<HostView> result;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto found = entries_.find(view);
    if (found == entries_.end()) {
      result = {};
    } else {
      result = found->second.result;
    }
  }
  if (!result.valid()) return load_(view);
  return result.get();
}

void ViewLoader::forgetBefore(int step) {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = entries_.begin(); it != entries_.end();) {
    // A view still loading stays until its load ends (its task refers to this loader).
    const bool done =
        it->second.result.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    if (it->second.last_step < step && done) {
      it = entries_.erase(it);
    } else {
      ++it;
    }
  }
}

std::size_t ViewLoader::held() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

}  // namespace gaussians
}  // namespace sadsplat
