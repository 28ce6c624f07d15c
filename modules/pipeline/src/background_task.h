#pragma once
/// \file background_task.h
/// \brief One piece of work at a time on another thread (the training's checkpoint writes): the
/// caller goes on while it runs and learns of its failure at the next start() or wait().

#include <functional>
#include <future>
#include <utility>

namespace sadsplat {
namespace pipeline {

class BackgroundTask {
 public:
  BackgroundTask() = default;
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;
  /// Waits for a task still running; its error is dropped (the exception that is unwinding the
  /// caller, if any, is the one to report).
  ~BackgroundTask() {
    if (pending_.valid()) pending_.wait();
  }

  /// \brief Waits for the previous task (rethrowing its error), then starts `work`.
  void start(std::function<void()> work) {
    wait();
    pending_ = std::async(std::launch::async, std::move(work));
  }
  /// \brief Waits for the running task, if any; rethrows what it threw.
  void wait() {
    if (pending_.valid()) pending_.get();
  }

 private:
  std::future<void> pending_;
};

}  // namespace pipeline
}  // namespace sadsplat
