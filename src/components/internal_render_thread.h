#pragma once
// The thread that owns sim.cameras' renderer. Its GL context is current there and nowhere
// else, so the loop's thread only waits for frames. On a software rasteriser (llvmpipe) the
// calling thread of GL does the vertex work and waits for every pass a later pass samples: a
// pipelined camera that drew on the loop's thread held the loop for the whole draw, and
// nothing else (a GUI's commands, the perception of the frame before) could run meanwhile.
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>

namespace saccade::components::internal {

class RenderThread {
 public:
  RenderThread();
  /// Runs what was posted, then joins.
  ~RenderThread();
  RenderThread(const RenderThread&) = delete;
  RenderThread& operator=(const RenderThread&) = delete;

  /// Runs `job` on the thread, after those posted before it; the future holds its result, or
  /// the exception it threw.
  template <class F>
  auto Post(F job) -> std::future<decltype(job())> {
    using Result = decltype(job());
    auto task = std::make_shared<std::packaged_task<Result()>>(std::move(job));
    std::future<Result> future = task->get_future();
    Enqueue([task] { (*task)(); });
    return future;
  }

 private:
  void Enqueue(std::function<void()> job);
  void Loop();

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> jobs_;
  bool stop_ = false;
  std::thread thread_;
};

/// How often Await calls `while_waiting`, at most.
inline constexpr auto kWhileWaitingPeriod = std::chrono::milliseconds(2);

/// The future's value (its exception rethrown). While it is not ready, calls `while_waiting`
/// (when given: runtime::StepContext::while_waiting): at once, then every kWhileWaitingPeriod.
template <class T>
T Await(std::future<T> future, const std::function<void()>* while_waiting) {
  if (while_waiting != nullptr && *while_waiting) {
    while (future.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      (*while_waiting)();
      future.wait_for(kWhileWaitingPeriod);
    }
  }
  return future.get();
}

}  // namespace saccade::components::internal
