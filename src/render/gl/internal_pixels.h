#pragma once
// Pixel conversion of the readback.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace saccade::render::gl {

/// Images of at least this many pixels get their CPU noise in two halves on two threads
/// (Retrieve); smaller ones in one piece, where a thread costs more than it saves.
constexpr std::size_t kMinSplitNoisePixels = 256 * 256;

/// RGBA rows to tightly packed RGB (alpha dropped); SSSE3 where the CPU has it.
void RgbaToRgb(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels);

/// The final pass's sensor noise (kFinalFragmentSource, NOISE) as a table: entry (DN << 10) |
/// code is DN plus sqrt(read_sigma^2 + gain * DN) times the deviate of 10-bit `code`
/// (PackGaussianTable's), rounded and clamped to 8 bits, in the pass's float arithmetic; then 3
/// bytes of padding (the vector loop's gathers read 4 bytes an entry).
std::vector<uint8_t> NoiseLevels(float read_sigma_dn, float gain_dn_per_e);

/// That noise on the CPU: `rgba` rows of `width` pixels, row 0 at the top (the pass's
/// gl_FragCoord.y), to tightly packed RGB, each channel through `levels` (NoiseLevels) with
/// the code of the entry of `table` (PackGaussianTable) that the pass's hash of the pixel and
/// `key` picks.
void RgbaToRgbWithNoise(const uint8_t* rgba, uint8_t* rgb, int width, int height, uint32_t key,
                        const uint32_t* table, const uint8_t* levels);

/// The same for rows [first_row, end_row) of the image only (`rgba` and `rgb` still point at
/// row 0), so that parts of one image can be converted at the same time.
void RgbaToRgbWithNoise(const uint8_t* rgba, uint8_t* rgb, int width, int first_row, int end_row,
                        uint32_t key, const uint32_t* table, const uint8_t* levels);

/// One row: row `y` of the image (its place in the hash) from `rgba_row` into `rgb_row`;
/// eight pixels at a time with AVX2 where the CPU has it (`simd` false: the portable loop, for
/// tests: the two give the same bytes).
void RgbaRowToRgbWithNoise(const uint8_t* rgba_row, uint8_t* rgb_row, int width, int y,
                           uint32_t key, const uint32_t* table, const uint8_t* levels,
                           bool simd = true);

}  // namespace saccade::render::gl
