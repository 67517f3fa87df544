#include "render/gl/internal_pixels.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <thread>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "render/gl/internal_effects.h"

namespace saccade::render::gl {
namespace {

// RGBA rows to tightly packed RGB (alpha dropped), portable: four pixels at a time, 16 bytes
// in, 12 bytes out, as three little-endian 32-bit words.
void RgbaToRgbPortable(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels) {
  static_assert(std::endian::native == std::endian::little);
  std::size_t i = 0;
  for (; i + 4 <= pixels; i += 4, rgba += 16, rgb += 12) {
    uint32_t p[4];
    std::memcpy(p, rgba, 16);
    const uint32_t out[3] = {(p[0] & 0x00FFFFFFu) | (p[1] << 24),
                             ((p[1] >> 8) & 0x0000FFFFu) | (p[2] << 16),
                             ((p[2] >> 16) & 0x000000FFu) | (p[3] << 8)};
    std::memcpy(rgb, out, 12);
  }
  for (; i < pixels; ++i, rgba += 4, rgb += 3) {
    rgb[0] = rgba[0];
    rgb[1] = rgba[1];
    rgb[2] = rgba[2];
  }
}

#if defined(__x86_64__)
// The same with one SSSE3 byte shuffle per four pixels (x86-64 CPUs have had SSSE3 since
// 2006; chosen at run time). Each 16-byte store overlaps the next by 4 bytes, so the last
// pixels go through the portable loop to stay inside `rgb`.
__attribute__((target("ssse3"))) void RgbaToRgbSsse3(const uint8_t* rgba, uint8_t* rgb,
                                                     std::size_t pixels) {
  const __m128i shuffle = _mm_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
  std::size_t i = 0;
  for (; i + 6 <= pixels; i += 4, rgba += 16, rgb += 12) {
    const __m128i in = _mm_loadu_si128(reinterpret_cast<const __m128i*>(rgba));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(rgb), _mm_shuffle_epi8(in, shuffle));
  }
  RgbaToRgbPortable(rgba, rgb, pixels - i);
}
#endif

}  // namespace

void RgbaToRgb(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels) {
#if defined(__x86_64__)
  static const bool ssse3 = __builtin_cpu_supports("ssse3");
  if (ssse3) return RgbaToRgbSsse3(rgba, rgb, pixels);
#endif
  RgbaToRgbPortable(rgba, rgb, pixels);
}

void RgbaToRgbInParts(const uint8_t* rgba, uint8_t* rgb, std::size_t pixels, unsigned threads) {
  const std::size_t parts =
      std::min<std::size_t>({std::max(1u, threads), 8, pixels / kMinConvertPartPixels});
  if (parts <= 1) {
    RgbaToRgb(rgba, rgb, pixels);
    return;
  }
  // Each part's SSSE3 stores stay inside its own range (RgbaToRgbSsse3).
  const std::size_t step = (pixels + parts - 1) / parts;
  std::vector<std::thread> others;
  for (std::size_t from = step; from < pixels; from += step) {
    others.emplace_back(RgbaToRgb, rgba + 4 * from, rgb + 3 * from, std::min(step, pixels - from));
  }
  RgbaToRgb(rgba, rgb, std::min(step, pixels));
  for (std::thread& other : others) other.join();
}

namespace {

// lowbias32 (C. Wellons), as kFinalFragmentSource's Hash.
inline uint32_t Hash(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

}  // namespace

std::vector<uint8_t> NoiseLevels(float read_sigma_dn, float gain_dn_per_e) {
  const float step = static_cast<float>(kGaussianStep);
  const float range = static_cast<float>(kGaussianRange);
  std::vector<uint8_t> levels(256 * 1024);
  for (int dn = 0; dn < 256; ++dn) {
    const float value = static_cast<float>(dn);
    const float sigma = std::sqrt(read_sigma_dn * read_sigma_dn + gain_dn_per_e * value);
    for (int code = 0; code < 1024; ++code) {
      const float z = static_cast<float>(code) * step - range;
      const float noisy = std::floor(value + sigma * z + 0.5f);
      levels[(dn << 10) | code] = static_cast<uint8_t>(std::clamp(noisy, 0.0f, 255.0f));
    }
  }
  return levels;
}

void RgbaToRgbWithNoise(const uint8_t* rgba, uint8_t* rgb, int width, int first_row, int end_row,
                        const CpuNoise& noise) {
  for (int y = first_row; y < end_row; ++y) {
    RgbaRowToRgbWithNoise(rgba + static_cast<std::size_t>(y) * width * 4,
                          rgb + static_cast<std::size_t>(y) * width * 3, width, y, noise);
  }
}

namespace {

void RgbaRowToRgbWithNoisePortable(const uint8_t* in, uint8_t* out, int first, int width,
                                   uint32_t row, const CpuNoise& noise) {
  const uint32_t* table = noise.table;
  const uint8_t* levels = noise.levels;
  in += 4 * static_cast<std::size_t>(first);
  out += 3 * static_cast<std::size_t>(first);
  for (int x = first; x < width; ++x, in += 4, out += 3) {
    const uint32_t g = table[Hash(static_cast<uint32_t>(x) ^ row) & 0xFFFFu];
    out[0] = levels[(static_cast<uint32_t>(in[0]) << 10) | (g & 1023u)];
    out[1] = levels[(static_cast<uint32_t>(in[1]) << 10) | ((g >> 10) & 1023u)];
    out[2] = levels[(static_cast<uint32_t>(in[2]) << 10) | ((g >> 20) & 1023u)];
  }
}

#if defined(__x86_64__)
// Channel c of eight pixels `p` (RGBA) with the deviates' codes of their entries `g`: the
// levels' formula (NoiseLevels) in eight lanes, the same float operations in the same order
// (no fused multiply-add), so the same bytes as the table: checked for every DN and code.
__attribute__((target("avx2"))) inline __m256i NoisyChannel(__m256i p, __m256i g, int c,
                                                            __m256 read_variance, __m256 gain) {
  const __m256 dn =
      _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(p, 8 * c), _mm256_set1_epi32(0xFF)));
  const __m256i code = _mm256_and_si256(_mm256_srli_epi32(g, 10 * c), _mm256_set1_epi32(1023));
  const __m256 z = _mm256_sub_ps(
      _mm256_mul_ps(_mm256_cvtepi32_ps(code), _mm256_set1_ps(static_cast<float>(kGaussianStep))),
      _mm256_set1_ps(static_cast<float>(kGaussianRange)));
  const __m256 sigma = _mm256_sqrt_ps(_mm256_add_ps(read_variance, _mm256_mul_ps(gain, dn)));
  const __m256 noisy = _mm256_floor_ps(
      _mm256_add_ps(_mm256_add_ps(dn, _mm256_mul_ps(sigma, z)), _mm256_set1_ps(0.5f)));
  return _mm256_cvttps_epi32(
      _mm256_min_ps(_mm256_max_ps(noisy, _mm256_setzero_ps()), _mm256_set1_ps(255.0f)));
}

// The same, eight pixels at a time: the hash in eight lanes, the table's entry gathered, each
// channel's noisy value computed (three gathers from the levels cost more than the arithmetic
// on this machine's CPU: 7.0 against 2.5 ms a 1024 x 768 image on one thread), and the RGB0
// words packed to RGB by one byte shuffle per four pixels. Each half's 16-byte store overlaps
// the next pixel's 4 bytes, so the last pixels go through the portable loop.
__attribute__((target("avx2"))) void RgbaRowToRgbWithNoiseAvx2(const uint8_t* in, uint8_t* out,
                                                               int width, uint32_t row,
                                                               const CpuNoise& noise) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i row_key = _mm256_set1_epi32(static_cast<int>(row));
  const __m256i m1 = _mm256_set1_epi32(0x7feb352d);
  const __m256i m2 = _mm256_set1_epi32(static_cast<int>(0x846ca68bu));
  const __m256i entry = _mm256_set1_epi32(0xFFFF);
  const __m128i rgb = _mm_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1);
  const __m256 read_variance = _mm256_set1_ps(noise.read_sigma_dn * noise.read_sigma_dn);
  const __m256 gain = _mm256_set1_ps(noise.gain_dn_per_e);
  int x = 0;
  for (; x + 8 < width; x += 8) {
    __m256i h = _mm256_xor_si256(_mm256_add_epi32(_mm256_set1_epi32(x), lane), row_key);
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 16));
    h = _mm256_mullo_epi32(h, m1);
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 15));
    h = _mm256_mullo_epi32(h, m2);
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 16));
    const __m256i g = _mm256_i32gather_epi32(reinterpret_cast<const int*>(noise.table),
                                             _mm256_and_si256(h, entry), 4);
    const __m256i p = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + 4 * x));
    const __m256i r = NoisyChannel(p, g, 0, read_variance, gain);
    const __m256i gr = NoisyChannel(p, g, 1, read_variance, gain);
    const __m256i b = NoisyChannel(p, g, 2, read_variance, gain);
    const __m256i words =
        _mm256_or_si256(r, _mm256_or_si256(_mm256_slli_epi32(gr, 8), _mm256_slli_epi32(b, 16)));
    uint8_t* o = out + 3 * static_cast<std::size_t>(x);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(o),
                     _mm_shuffle_epi8(_mm256_castsi256_si128(words), rgb));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(o + 12),
                     _mm_shuffle_epi8(_mm256_extracti128_si256(words, 1), rgb));
  }
  RgbaRowToRgbWithNoisePortable(in, out, x, width, row, noise);
}
#endif

}  // namespace

void RgbaRowToRgbWithNoise(const uint8_t* rgba_row, uint8_t* rgb_row, int width, int y,
                           const CpuNoise& noise, bool simd) {
  const uint32_t row = Hash(static_cast<uint32_t>(y) ^ noise.key);
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && simd) return RgbaRowToRgbWithNoiseAvx2(rgba_row, rgb_row, width, row, noise);
#else
  static_cast<void>(simd);
#endif
  RgbaRowToRgbWithNoisePortable(rgba_row, rgb_row, 0, width, row, noise);
}

}  // namespace saccade::render::gl
