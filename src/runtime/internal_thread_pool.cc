#include "runtime/internal_thread_pool.h"

namespace saccade::runtime::internal {

ThreadPool::ThreadPool(int threads) {
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { Work(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

bool ThreadPool::TakeShared(std::size_t* index) {
  // Under the lock: the next task that may run on any thread.
  while (next_ < n_) {
    const std::size_t i = next_++;
    if (affine_ != nullptr && i < affine_->size() && (*affine_)[i]) continue;
    *index = i;
    return true;
  }
  return false;
}

void ThreadPool::Work() {
  std::size_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return quit_ || generation_ != seen; });
    if (quit_) return;
    seen = generation_;
    std::size_t i = 0;
    while (TakeShared(&i)) {
      lock.unlock();
      (*task_)(i);
      lock.lock();
      if (--remaining_ == 0) done_.notify_all();
    }
  }
}

void ThreadPool::Run(std::size_t n, const std::function<void(std::size_t)>& task,
                     const std::vector<bool>& affine) {
  if (workers_.empty() || n <= 1) {
    for (std::size_t i = 0; i < n; ++i) task(i);
    return;
  }
  std::unique_lock<std::mutex> lock(mutex_);
  task_ = &task;
  affine_ = &affine;
  n_ = n;
  next_ = 0;
  remaining_ = n;
  ++generation_;
  wake_.notify_all();
  // The affine tasks here first, then a share of the others.
  for (std::size_t i = 0; i < n && i < affine.size(); ++i) {
    if (!affine[i]) continue;
    lock.unlock();
    task(i);
    lock.lock();
    --remaining_;
  }
  std::size_t i = 0;
  while (TakeShared(&i)) {
    lock.unlock();
    task(i);
    lock.lock();
    --remaining_;
  }
  done_.wait(lock, [&] { return remaining_ == 0; });
  task_ = nullptr;
  affine_ = nullptr;
  n_ = 0;
}

}  // namespace saccade::runtime::internal
