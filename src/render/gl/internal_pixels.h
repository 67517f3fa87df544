#pragma once
// Pixel conversion of the readback.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/internal_chunks.h"

namespace saccade::render::gl {

/// Images of at least this many pixels get their CPU work after readback in chunks of rows on
/// every core (InRowChunks); smaller ones in one piece, where waking a thread costs more than it
/// saves.
constexpr std::size_t kMinSplitNoisePixels = 256 * 256;

/// part(first_row, end_row) over rows [0, rows) of an image of `pixels` pixels: in chunks of
/// rows on every core (internal::ForEachRowChunk) where there are at least kMinSplitNoisePixels
/// pixels (Retrieve runs after the frame's fence, when a software rasteriser's threads are
/// idle), else in one piece. The same result either way where each row is computed alone.
template <class Part>
void InRowChunks(int rows, std::size_t pixels, const Part& part) {
  if (pixels < kMinSplitNoisePixels) {
    part(0, rows);
    return;
  }
  render::internal::ForEachRowChunk(rows, [&part](int, int first, int end) { part(first, end); });
}

/// RGBA rows to tightly packed RGB (alpha dropped); SSSE3 where the CPU has it.
void RgbaToRgb(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels);

/// The fewest pixels of a part of RgbaToRgbInParts: about a millisecond of one thread's work
/// (reading a mapped pixel buffer), against some 50 us to start a thread.
constexpr std::size_t kMinConvertPartPixels = std::size_t{1} << 20;

/// RgbaToRgb in parts of at least kMinConvertPartPixels, at most `threads` (and 8) at once,
/// each on a thread of its own: the same bytes. For a large batch's readback (RenderBatch).
void RgbaToRgbInParts(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels, unsigned threads);

/// The final pass's sensor noise (kFinalFragmentSource, NOISE) as a table: entry (DN << 10) |
/// code is DN plus sqrt(read_sigma^2 + gain * DN) times the deviate of 10-bit `code`
/// (PackGaussianTable's), rounded and clamped to 8 bits, in the pass's float arithmetic.
std::vector<uint8_t> NoiseLevels(float read_sigma_dn, float gain_dn_per_e);

/// One camera's noise in one frame, as the CPU adds it: the pass's hash of the pixel and `key`
/// picks an entry of `table` (PackGaussianTable), whose codes give each channel's deviate;
/// `levels` is NoiseLevels(read_sigma_dn, gain_dn_per_e), the vector loop computes the same.
struct CpuNoise {
  uint32_t key = 0;
  float read_sigma_dn = 0.0f;
  float gain_dn_per_e = 0.0f;
  const uint32_t* table = nullptr;
  const uint8_t* levels = nullptr;
};

/// That noise on the CPU: rows [first_row, end_row) of `rgba` (rows of `width` pixels, row 0
/// at the top: the pass's gl_FragCoord.y) to tightly packed RGB in `rgb` (`rgba` and `rgb`
/// point at row 0, so that parts of one image can be converted at the same time).
void RgbaToRgbWithNoise(const uint8_t* rgba, uint8_t* rgb, int width, int first_row, int end_row,
                        const CpuNoise& noise);

/// One row: row `y` of the image (its place in the hash) from `rgba_row` into `rgb_row`;
/// eight pixels at a time with AVX2 where the CPU has it (`simd` false: the portable loop
/// through the levels, for tests: the two give the same bytes).
void RgbaRowToRgbWithNoise(const uint8_t* rgba_row, uint8_t* rgb_row, int width, int y,
                           const CpuNoise& noise, bool simd = true);

}  // namespace saccade::render::gl
