// The render module's chunks on every core (render/internal_chunks.h): every value once, in
// chunks at multiples of the grain, slots that tell threads apart, several callers and calls
// from inside a chunk at once, errors passed back, and a forked child that has no workers.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "render/internal_chunks.h"

namespace saccade::render::internal {
namespace {

// What one call of ForEachChunk did: how often each value was visited, the chunks it was given
// and which threads ran each slot.
struct Visits {
  explicit Visits(std::size_t n) : counts(n) {}
  std::vector<std::atomic<int>> counts;
  std::mutex mutex;
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
  std::map<int, std::set<std::thread::id>> threads_of_slot;

  Chunk Recorder() {
    return [this](int slot, std::size_t first, std::size_t end) {
      for (std::size_t i = first; i < end; ++i) counts[i].fetch_add(1);
      std::lock_guard lock(mutex);
      chunks.emplace_back(first, end);
      threads_of_slot[slot].insert(std::this_thread::get_id());
    };
  }

  void ExpectEachOnce(std::size_t grain) {
    for (std::size_t i = 0; i < counts.size(); ++i) ASSERT_EQ(counts[i].load(), 1) << "value " << i;
    for (const auto& [first, end] : chunks) {
      EXPECT_EQ(first % grain, 0u) << "chunk [" << first << ", " << end << ")";
      EXPECT_EQ(end, std::min(counts.size(), first + grain)) << "chunk at " << first;
    }
    for (const auto& [slot, threads] : threads_of_slot) {
      EXPECT_GE(slot, 0);
      EXPECT_LT(slot, ChunkSlots());
      EXPECT_EQ(threads.size(), 1u) << "slot " << slot << " ran on several threads in one call";
    }
  }
};

TEST(ChunksTest, EveryValueOnceInChunksAtMultiplesOfTheGrain) {
  for (const std::size_t n : {1u, 7u, 64u, 1000u, 100003u}) {
    Visits visits(n);
    ForEachChunk(n, 64, visits.Recorder());
    visits.ExpectEachOnce(64);
    EXPECT_EQ(visits.chunks.size(), (n + 63) / 64) << "n = " << n;
  }
  ForEachChunk(0, 8, [](int, std::size_t, std::size_t) { FAIL() << "a chunk of nothing"; });
}

TEST(ChunksTest, AWholeWithinOneGrainRunsOnTheCallingThread) {
  std::vector<std::tuple<int, std::size_t, std::size_t, std::thread::id>> calls;
  ForEachChunk(32, 32, [&](int slot, std::size_t first, std::size_t end) {
    calls.emplace_back(slot, first, end, std::this_thread::get_id());
  });
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_EQ(calls[0],
            std::make_tuple(0, std::size_t{0}, std::size_t{32}, std::this_thread::get_id()));
}

TEST(ChunksTest, RowChunksCoverEveryRow) {
  std::vector<int> rows(775, 0);
  ForEachRowChunk(775, [&](int, int first, int end) {
    for (int y = first; y < end; ++y) ++rows[static_cast<std::size_t>(y)];
  });
  for (std::size_t y = 0; y < rows.size(); ++y) EXPECT_EQ(rows[y], 1) << "row " << y;
}

// Two eyes' chains at once, each of whose chunks makes calls of its own (the depth of field's
// rows inside a camera's chain): all finish, each value visited once.
TEST(ChunksTest, CallersAtOnceAndCallsFromInsideChunksAllFinish) {
  constexpr std::size_t kOuter = 12, kInner = 5000;
  std::vector<std::unique_ptr<Visits>> inner;
  for (std::size_t i = 0; i < 2 * kOuter; ++i) inner.push_back(std::make_unique<Visits>(kInner));
  Visits outer[2] = {Visits(kOuter), Visits(kOuter)};
  const auto eye = [&](int e) {
    const Chunk record = outer[e].Recorder();
    ForEachChunk(kOuter, 1, [&](int slot, std::size_t first, std::size_t end) {
      record(slot, first, end);
      for (std::size_t k = first; k < end; ++k) {
        ForEachChunk(kInner, 100, inner[e * kOuter + k]->Recorder());
      }
    });
  };
  std::thread other(eye, 1);
  eye(0);
  other.join();
  outer[0].ExpectEachOnce(1);
  outer[1].ExpectEachOnce(1);
  for (const auto& visits : inner) visits->ExpectEachOnce(100);
}

TEST(ChunksTest, AChunksErrorReachesTheCallerAndThePoolGoesOn) {
  std::atomic<int> ran{0};
  EXPECT_THROW(ForEachChunk(100, 10,
                            [&](int, std::size_t first, std::size_t) {
                              ++ran;
                              if (first == 50) throw std::runtime_error("chunk at 50");
                            }),
               std::runtime_error);
  EXPECT_EQ(ran.load(), 10) << "every chunk runs before the call returns";
  Visits after(1000);
  ForEachChunk(1000, 10, after.Recorder());
  after.ExpectEachOnce(10);
}

// Children forked while another thread keeps the workers busy (the pool's lock taken and
// given back all the time) run their own chunks and finish: none inherits the lock taken.
TEST(ChunksTest, ChildrenForkedWhileTheWorkersRunFinishTheirChunks) {
  std::atomic<bool> stop{false};
  std::thread busy([&] {
    while (!stop) ForEachChunk(4000, 1, [](int, std::size_t, std::size_t) {});
  });
  int hung = 0, wrong = 0;
  for (int round = 0; round < 30; ++round) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      std::vector<int> counts(10000, 0);
      ForEachChunk(10000, 10, [&](int, std::size_t first, std::size_t end) {
        for (std::size_t i = first; i < end; ++i) ++counts[i];
      });
      for (const int c : counts) {
        if (c != 1) _exit(1);
      }
      _exit(0);
    }
    int status = 0;
    pid_t done = 0;
    for (int wait_ms = 0; wait_ms < 5000 && done == 0; wait_ms += 5) {
      done = waitpid(child, &status, WNOHANG);
      if (done == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (done == 0) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      ++hung;
    } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      ++wrong;
    }
  }
  stop = true;
  busy.join();
  EXPECT_EQ(hung, 0) << "children that never finished (a lock inherited taken)";
  EXPECT_EQ(wrong, 0) << "children that visited some value other than once";
}

}  // namespace
}  // namespace saccade::render::internal
