#include "render/gl/internal_pixels.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>

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

void RgbaToRgbWithNoise(const uint8_t* rgba, uint8_t* rgb, int width, int height, uint32_t key,
                        const uint32_t* table, const uint8_t* levels) {
  RgbaToRgbWithNoise(rgba, rgb, width, 0, height, key, table, levels);
}

void RgbaToRgbWithNoise(const uint8_t* rgba, uint8_t* rgb, int width, int first_row, int end_row,
                        uint32_t key, const uint32_t* table, const uint8_t* levels) {
  for (int y = first_row; y < end_row; ++y) {
    const uint32_t row = Hash(static_cast<uint32_t>(y) ^ key);
    const uint8_t* in = rgba + static_cast<std::size_t>(y) * width * 4;
    uint8_t* out = rgb + static_cast<std::size_t>(y) * width * 3;
    for (int x = 0; x < width; ++x, in += 4, out += 3) {
      const uint32_t g = table[Hash(static_cast<uint32_t>(x) ^ row) & 0xFFFFu];
      out[0] = levels[(static_cast<uint32_t>(in[0]) << 10) | (g & 1023u)];
      out[1] = levels[(static_cast<uint32_t>(in[1]) << 10) | ((g >> 10) & 1023u)];
      out[2] = levels[(static_cast<uint32_t>(in[2]) << 10) | ((g >> 20) & 1023u)];
    }
  }
}

}  // namespace saccade::render::gl
