#include "internal_chunks.h"

#include <pthread.h>

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace saccade::render::internal {
namespace {

// One call of ForEachChunk: its chunks are claimed in order, under the pool's lock.
struct Call {
  const Chunk* chunk = nullptr;
  std::size_t n = 0, grain = 0, chunks = 0;
  std::size_t claimed = 0;  // chunks started
  std::size_t done = 0;     // chunks finished
  std::exception_ptr error;
};

// The workers and the calls with chunks left. Made once and never destroyed: its threads wait
// for work until the process ends (a static destructor would join them while a caller on
// another thread may still need them).
class Pool {
 public:
  explicit Pool(int workers) {
    for (int slot = 1; slot <= workers; ++slot) std::thread([this, slot] { Work(slot); }).detach();
  }

  static Pool& Get() {
    static Pool* const pool = [] {
      made_ = new Pool(ChunkSlots() - 1);
      // A child forked from a process with workers has none: it runs every chunk of its calls
      // itself (nobody else claims them). The lock is held across the fork so that the child
      // never inherits it taken by a worker.
      pthread_atfork(&BeforeFork, &AfterForkInParent, &AfterForkInChild);
      return made_;
    }();
    return *pool;
  }

  void Run(Call* call) {
    std::unique_lock lock(mutex_);
    open_.push_back(call);
    wake_.notify_all();
    while (call->claimed < call->chunks) RunOne(call, 0, &lock);
    done_.wait(lock, [call] { return call->done == call->chunks; });
    if (call->error) std::rethrow_exception(call->error);
  }

 private:
  // Claims `call`'s next chunk and runs it on `slot` with the lock released.
  void RunOne(Call* call, int slot, std::unique_lock<std::mutex>* lock) {
    const std::size_t index = call->claimed++;
    if (call->claimed == call->chunks) std::erase(open_, call);
    lock->unlock();
    const std::size_t first = index * call->grain;
    std::exception_ptr error;
    try {
      (*call->chunk)(slot, first, std::min(call->n, first + call->grain));
    } catch (...) {
      error = std::current_exception();
    }
    lock->lock();
    if (error && !call->error) call->error = error;
    if (++call->done == call->chunks) done_.notify_all();
  }

  void Work(int slot) {
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return !open_.empty(); });
      RunOne(open_.front(), slot, &lock);
    }
  }

  static void BeforeFork() { made_->mutex_.lock(); }
  static void AfterForkInParent() { made_->mutex_.unlock(); }
  static void AfterForkInChild() {
    made_->open_.clear();  // the parent's calls: nobody here runs them
    made_->mutex_.unlock();
  }

  static inline Pool* made_ = nullptr;
  std::mutex mutex_;
  std::condition_variable wake_;  // a call was opened
  std::condition_variable done_;  // a call's last chunk finished
  std::vector<Call*> open_;       // calls with chunks nobody has claimed, oldest first
};

}  // namespace

int ChunkSlots() {
  static const int slots = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return slots;
}

void ForEachChunk(std::size_t n, std::size_t grain, const Chunk& chunk) {
  if (n == 0) return;
  grain = std::max<std::size_t>(grain, 1);
  if (n <= grain || ChunkSlots() < 2) {
    chunk(0, 0, n);
    return;
  }
  Call call;
  call.chunk = &chunk;
  call.n = n;
  call.grain = grain;
  call.chunks = (n + grain - 1) / grain;
  Pool::Get().Run(&call);
}

}  // namespace saccade::render::internal
