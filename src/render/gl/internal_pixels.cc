#include "render/gl/internal_pixels.h"

#include <bit>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

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

}  // namespace saccade::render::gl
