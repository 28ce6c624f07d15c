#pragma once
// Views read from a scene cache on loader threads ahead of the steps that use them (streamed
// views of a scene read without pixels): the trainer asks for the views of the coming steps, a
// loader thread reads, decodes and converts each, and the step takes it. Host memory: the views
// of the steps asked for, not the scene.

#include <ATen/ATen.h>

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

namespace sadsplat {
namespace gaussians {

// A view's pictures in host memory as streamed views keep them, and what the trainer keeps of
// the view when its pictures go (filled when loaded with summaries).
struct HostView {
  at::Tensor image;       // [H, W, 3] uint8
  at::Tensor mask;        // [H, W] uint8, 255 = valid pixel
  at::Tensor labels;      // [H, W] int16 supervision, -1 = none; undefined: no pixel supervised
  at::Tensor confidence;  // [H, W] float: the drop's confidence map (undefined: none)
  bool mask_is_full = false;
  bool ground_truth = false;  // labels are the view's ground truth (not pseudo-labels)
};

class ViewLoader {
 public:
  using Load = std::function<HostView(int view)>;
  // `threads` loader threads (at least 1) calling `load`.
  ViewLoader(Load load, int threads);
  ~ViewLoader();
  ViewLoader(const ViewLoader&) = delete;
  ViewLoader& operator=(const ViewLoader&) = delete;

  // Starts loading `view`, which step `step` uses, unless it is loading or loaded already.
  void request(int view, int step);
  // View `view`: waits for its load, or loads it on this thread when it was never requested (and
  // then keeps nothing). Rethrows the load's error.
  HostView take(int view);
  // Forgets the views no step from `step` on asked for.
  void forgetBefore(int step);
  // How many views are loading or loaded.
  std::size_t held() const;

 private:
  struct Entry {
    std::shared_future<HostView> result;
    int last_step = 0;
  };
  void work();

  Load load_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::packaged_task<HostView()>> queue_;
  std::map<int, Entry> entries_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace gaussians
}  // namespace sadsplat
