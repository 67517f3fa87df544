#pragma once
// The cameras' CPU work in chunks of rows on every core: a pool of the render module's own,
// made on first use, with one thread fewer than the cores (the calling thread works too).
// Private to render.
//
// The camera chain after readback (the lens remap, vignetting, depth of field, the sensor,
// demosaicing) computes each row, or each value, alone: split in chunks it gives the same bits
// on any number of threads. Several callers may run at once (both eyes of a head, each on a
// thread of its own): the workers take chunks from every call that has some left, and each
// caller works through its own call's chunks until none are left, so a call never waits for a
// chunk that nobody has started, and a call made from inside a chunk cannot deadlock.
#include <algorithm>
#include <cstddef>
#include <functional>

namespace saccade::render::internal {

/// chunk(slot, first, end) over [0, n): chunks of `grain` values (the last may be shorter),
/// each starting at a multiple of `grain`. `slot` < ChunkSlots() tells apart the threads that
/// run a call's chunks at the same time (the caller is 0), for per-thread scratch and sums.
/// Returns once every chunk is done; the first exception a chunk threw is rethrown then.
/// `n` <= `grain` (or one core) runs chunk(0, 0, n) on the calling thread.
using Chunk = std::function<void(int slot, std::size_t first, std::size_t end)>;
void ForEachChunk(std::size_t n, std::size_t grain, const Chunk& chunk);

/// The threads a call of ForEachChunk may use at once: the cores (1 at least).
int ChunkSlots();

/// Rows a chunk of per-row work takes by default: 32 rows of a 1024-pixel-wide image are tens
/// of microseconds of work, against a few to wake a worker.
constexpr int kRowChunk = 32;

/// ForEachChunk over the rows [0, height) of an image, `grain` rows a chunk:
/// rows(slot, first_row, end_row).
template <typename Rows>
void ForEachRowChunk(int height, const Rows& rows, int grain = kRowChunk) {
  ForEachChunk(static_cast<std::size_t>(std::max(height, 0)), static_cast<std::size_t>(grain),
               [&rows](int slot, std::size_t first, std::size_t end) {
                 rows(slot, static_cast<int>(first), static_cast<int>(end));
               });
}

}  // namespace saccade::render::internal
