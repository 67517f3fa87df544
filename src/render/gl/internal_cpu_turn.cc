#include "render/gl/internal_cpu_turn.h"

#include <cmath>
#include <cstddef>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace saccade::render::gl {
namespace {

// A homography's rows, and its row-dependent terms for row y: q_r = h[r][0] x + c[r].
struct RowHomography {
  float h0[3];  // h(r, 0)
  float c[3];   // h(r, 1) y + h(r, 2), fused as the vector loop computes it
};

RowHomography ForRow(const Eigen::Matrix3f& h, int y) {
  RowHomography r;
  for (int i = 0; i < 3; ++i) {
    r.h0[i] = h(i, 0);
    r.c[i] = std::fma(h(i, 1), static_cast<float>(y), h(i, 2));
  }
  return r;
}

// A coordinate kept within [-1, size] (NaN to -1): past the edge the clamped fetch is the
// edge's anyway, and the conversion to an integer stays defined.
float Within(float v, float size) {
  v = v > -1.0f ? v : -1.0f;
  return v < size ? v : size;
}

int Clamp(int i, int last) { return i < 0 ? 0 : (i > last ? last : i); }

// Pixels [from, width) of the row, one at a time, in the vector loop's arithmetic.
void TurnBlurPortable(const CpuTurn& turn, const std::vector<RowHomography>& rows,
                      const uint8_t* pixels, int width, int height, int from, uint8_t* out) {
  const std::size_t layer_bytes = static_cast<std::size_t>(width) * height * 4;
  const float inv_n = 1.0f / static_cast<float>(rows.size());
  for (int x = from; x < width; ++x) {
    const float px = static_cast<float>(x);
    float sum[3] = {0.0f, 0.0f, 0.0f};
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const RowHomography& r = rows[k];
      const float qx = std::fma(r.h0[0], px, r.c[0]);
      const float qy = std::fma(r.h0[1], px, r.c[1]);
      const float qz = std::fma(r.h0[2], px, r.c[2]);
      const float inv = 1.0f / qz;
      const float u = Within(qx * inv, static_cast<float>(width));
      const float v = Within(qy * inv, static_cast<float>(height));
      const float fu = std::floor(u), fv = std::floor(v);
      const float ax = u - fu, ay = v - fv;
      const int x0 = static_cast<int>(fu), y0 = static_cast<int>(fv);
      const int c0 = Clamp(x0, width - 1), c1 = Clamp(x0 + 1, width - 1);
      const int r0 = Clamp(y0, height - 1) * width, r1 = Clamp(y0 + 1, height - 1) * width;
      const uint8_t* layer = pixels + static_cast<std::size_t>(turn.layers[k]) * layer_bytes;
      const uint8_t* t00 = layer + 4 * static_cast<std::size_t>(r0 + c0);
      const uint8_t* t01 = layer + 4 * static_cast<std::size_t>(r0 + c1);
      const uint8_t* t10 = layer + 4 * static_cast<std::size_t>(r1 + c0);
      const uint8_t* t11 = layer + 4 * static_cast<std::size_t>(r1 + c1);
      for (int c = 0; c < 3; ++c) {
        const float a = t00[c], b = t01[c], d = t10[c], e = t11[c];
        const float top = std::fma(ax, b - a, a);
        const float bottom = std::fma(ax, e - d, d);
        sum[c] += std::fma(ay, bottom - top, top);
      }
    }
    uint8_t* o = out + 4 * static_cast<std::size_t>(x);
    for (int c = 0; c < 3; ++c) {
      o[c] = static_cast<uint8_t>(static_cast<int>(std::floor(std::fma(sum[c], inv_n, 0.5f))));
    }
    o[3] = 255;
  }
}

#if defined(__x86_64__)
__attribute__((target("avx2"))) inline __m256i ClampLanes(__m256i i, __m256i last, __m256i zero) {
  return _mm256_max_epi32(_mm256_min_epi32(i, last), zero);
}

// Channel `shift` / 8 of eight RGBA8 texels, as floats.
__attribute__((target("avx2"))) inline __m256 Channel(__m256i texels, int shift, __m256i byte) {
  return _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(texels, shift), byte));
}

// Eight pixels at a time: the homography, the division and the four texels' gathers in eight
// lanes, each channel's bilinear weights in float with the portable loop's fused operations.
__attribute__((target("avx2,fma"))) int TurnBlurAvx2(const CpuTurn& turn,
                                                     const std::vector<RowHomography>& rows,
                                                     const uint8_t* pixels, int width, int height,
                                                     uint8_t* out) {
  const std::size_t layer_bytes = static_cast<std::size_t>(width) * height * 4;
  const __m256 lane = _mm256_setr_ps(0.f, 1.f, 2.f, 3.f, 4.f, 5.f, 6.f, 7.f);
  const __m256 low = _mm256_set1_ps(-1.0f);
  const __m256 high_x = _mm256_set1_ps(static_cast<float>(width));
  const __m256 high_y = _mm256_set1_ps(static_cast<float>(height));
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 half = _mm256_set1_ps(0.5f);
  const __m256 inv_n = _mm256_set1_ps(1.0f / static_cast<float>(rows.size()));
  const __m256i zero = _mm256_setzero_si256();
  const __m256i one_i = _mm256_set1_epi32(1);
  const __m256i last_x = _mm256_set1_epi32(width - 1);
  const __m256i last_y = _mm256_set1_epi32(height - 1);
  const __m256i stride = _mm256_set1_epi32(width);
  const __m256i byte = _mm256_set1_epi32(0xFF);
  const __m256i alpha = _mm256_set1_epi32(static_cast<int>(0xFF000000u));
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    const __m256 px = _mm256_add_ps(_mm256_set1_ps(static_cast<float>(x)), lane);
    __m256 sum[3] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const RowHomography& r = rows[k];
      const __m256 qx = _mm256_fmadd_ps(_mm256_set1_ps(r.h0[0]), px, _mm256_set1_ps(r.c[0]));
      const __m256 qy = _mm256_fmadd_ps(_mm256_set1_ps(r.h0[1]), px, _mm256_set1_ps(r.c[1]));
      const __m256 qz = _mm256_fmadd_ps(_mm256_set1_ps(r.h0[2]), px, _mm256_set1_ps(r.c[2]));
      const __m256 inv = _mm256_div_ps(one, qz);
      // max_ps returns its second operand for a NaN: -1, as Within.
      const __m256 u = _mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(qx, inv), low), high_x);
      const __m256 v = _mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(qy, inv), low), high_y);
      const __m256 fu = _mm256_floor_ps(u), fv = _mm256_floor_ps(v);
      const __m256 ax = _mm256_sub_ps(u, fu), ay = _mm256_sub_ps(v, fv);
      const __m256i x0 = _mm256_cvttps_epi32(fu), y0 = _mm256_cvttps_epi32(fv);
      const __m256i c0 = ClampLanes(x0, last_x, zero),
                    c1 = ClampLanes(_mm256_add_epi32(x0, one_i), last_x, zero);
      const __m256i r0 = _mm256_mullo_epi32(ClampLanes(y0, last_y, zero), stride);
      const __m256i r1 =
          _mm256_mullo_epi32(ClampLanes(_mm256_add_epi32(y0, one_i), last_y, zero), stride);
      const int* layer = reinterpret_cast<const int*>(
          pixels + static_cast<std::size_t>(turn.layers[k]) * layer_bytes);
      const __m256i t00 = _mm256_i32gather_epi32(layer, _mm256_add_epi32(r0, c0), 4);
      const __m256i t01 = _mm256_i32gather_epi32(layer, _mm256_add_epi32(r0, c1), 4);
      const __m256i t10 = _mm256_i32gather_epi32(layer, _mm256_add_epi32(r1, c0), 4);
      const __m256i t11 = _mm256_i32gather_epi32(layer, _mm256_add_epi32(r1, c1), 4);
      for (int c = 0; c < 3; ++c) {
        const __m256 a = Channel(t00, 8 * c, byte), b = Channel(t01, 8 * c, byte);
        const __m256 d = Channel(t10, 8 * c, byte), e = Channel(t11, 8 * c, byte);
        const __m256 top = _mm256_fmadd_ps(ax, _mm256_sub_ps(b, a), a);
        const __m256 bottom = _mm256_fmadd_ps(ax, _mm256_sub_ps(e, d), d);
        sum[c] = _mm256_add_ps(sum[c], _mm256_fmadd_ps(ay, _mm256_sub_ps(bottom, top), top));
      }
    }
    __m256i words = alpha;
    for (int c = 0; c < 3; ++c) {
      const __m256i value =
          _mm256_cvttps_epi32(_mm256_floor_ps(_mm256_fmadd_ps(sum[c], inv_n, half)));
      words = _mm256_or_si256(words, _mm256_slli_epi32(value, 8 * c));
    }
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 4 * static_cast<std::size_t>(x)), words);
  }
  return x;
}
#endif

}  // namespace

void TurnBlurRow(const CpuTurn& turn, const uint8_t* pixels, int width, int height, int y,
                 uint8_t* rgba_row, bool simd) {
  std::vector<RowHomography> rows;
  rows.reserve(turn.homographies.size());
  for (const Eigen::Matrix3f& h : turn.homographies) rows.push_back(ForRow(h, y));
  int from = 0;
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2 && simd) from = TurnBlurAvx2(turn, rows, pixels, width, height, rgba_row);
#else
  static_cast<void>(simd);
#endif
  TurnBlurPortable(turn, rows, pixels, width, height, from, rgba_row);
}

}  // namespace saccade::render::gl
