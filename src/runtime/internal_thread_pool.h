#pragma once
// A small pool of threads for the scheduler's parallel levels: Run(n, task) calls task(i) for
// i in [0, n) on the pool and on the calling thread, and returns once all are done. Tasks the
// caller marks `affine` (a component that owns an OpenGL context, say) run on the calling
// thread only. Private to runtime.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace saccade::runtime::internal {

class ThreadPool {
 public:
  /// `threads` counts the calling thread: 1 runs everything on it (no thread is started).
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  /// Runs task(i) for every i in [0, n); affine[i] (when given) keeps task i on this thread.
  /// Tasks must not throw.
  void Run(std::size_t n, const std::function<void(std::size_t)>& task,
           const std::vector<bool>& affine = {});

 private:
  void Work();
  bool TakeShared(std::size_t* index);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(std::size_t)>* task_ = nullptr;
  const std::vector<bool>* affine_ = nullptr;
  std::size_t n_ = 0;
  std::size_t next_ = 0;        // next task to take
  std::size_t remaining_ = 0;   // tasks not finished
  std::size_t generation_ = 0;  // one per Run
  bool quit_ = false;
};

}  // namespace saccade::runtime::internal
