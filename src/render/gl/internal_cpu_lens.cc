#include "render/gl/internal_cpu_lens.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace saccade::render::gl {
namespace {

// One bilinear sample of `source` (RGBA8, `stride` bytes a row), unrounded: each channel
// times 65536, in [0, 255 x 65536].
inline void Sample4(const uint8_t* source, uint32_t stride, uint32_t offset, uint32_t weights,
                    uint32_t sum[4]) {
  const uint8_t* p = source + offset;
  const uint8_t* q = p + stride;
  const uint32_t fx = weights & 0xFFFFu, fy = weights >> 16;
  for (int c = 0; c < 4; ++c) {
    const uint32_t top = p[c] * (256u - fx) + p[4 + c] * fx;
    const uint32_t bottom = q[c] * (256u - fx) + q[4 + c] * fx;
    sum[c] += top * (256u - fy) + bottom * fy;
  }
}

void RemapRowPortable(const uint8_t* source, uint32_t stride, const uint32_t* samples, int width,
                      uint8_t* out) {
  for (int x = 0; x < width; ++x, out += 4) {
    uint32_t sum[4] = {0, 0, 0, 0};
    Sample4(source, stride, samples[2 * x], samples[2 * x + 1], sum);
    for (int c = 0; c < 4; ++c) out[c] = static_cast<uint8_t>((sum[c] + 32768u) >> 16);
  }
}

#if defined(__x86_64__)
// The same, two pixels at a time: each pixel's two source rows of two pixels are shuffled to
// (r0 r1 g0 g1 b0 b1 a0 a1) and widened to 16 bits, so that one multiply-add with (256 - fx,
// fx) gives each row's horizontal blend; the vertical one is top 256 + (bottom - top) fy.
// Integer arithmetic throughout: equal to the portable loop to the bit.
__attribute__((target("avx2"))) void RemapRowAvx2(const uint8_t* source, uint32_t stride,
                                                  const uint32_t* samples, int width,
                                                  uint8_t* out) {
  const __m128i pairs = _mm_setr_epi8(0, 4, 1, 5, 2, 6, 3, 7, 8, 12, 9, 13, 10, 14, 11, 15);
  const __m128i zero = _mm_setzero_si128();
  const __m256i half = _mm256_set1_epi32(32768);
  int x = 0;
  for (; x + 2 <= width; x += 2, out += 8) {
    const uint32_t o0 = samples[2 * x], w0 = samples[2 * x + 1];
    const uint32_t o1 = samples[2 * x + 2], w1 = samples[2 * x + 3];
    const uint8_t* p0 = source + o0;
    const uint8_t* p1 = source + o1;
    __m128i a0 = _mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p0)),
                                    _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p0 + stride)));
    __m128i a1 = _mm_unpacklo_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p1)),
                                    _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p1 + stride)));
    a0 = _mm_shuffle_epi8(a0, pairs);
    a1 = _mm_shuffle_epi8(a1, pairs);
    const __m256i top = _mm256_set_m128i(_mm_unpacklo_epi8(a1, zero), _mm_unpacklo_epi8(a0, zero));
    const __m256i bottom =
        _mm256_set_m128i(_mm_unpackhi_epi8(a1, zero), _mm_unpackhi_epi8(a0, zero));
    const uint32_t fx0 = w0 & 0xFFFFu, fx1 = w1 & 0xFFFFu;
    const __m256i wx = _mm256_set_m128i(_mm_set1_epi32(static_cast<int>((256u - fx1) | fx1 << 16)),
                                        _mm_set1_epi32(static_cast<int>((256u - fx0) | fx0 << 16)));
    const __m256i wy = _mm256_set_m128i(_mm_set1_epi32(static_cast<int>(w1 >> 16)),
                                        _mm_set1_epi32(static_cast<int>(w0 >> 16)));
    const __m256i t = _mm256_madd_epi16(top, wx);
    const __m256i b = _mm256_madd_epi16(bottom, wx);
    __m256i v =
        _mm256_add_epi32(_mm256_slli_epi32(t, 8), _mm256_mullo_epi32(_mm256_sub_epi32(b, t), wy));
    v = _mm256_srli_epi32(_mm256_add_epi32(v, half), 16);
    const __m128i words =
        _mm_packus_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out), _mm_packus_epi16(words, words));
  }
  RemapRowPortable(source, stride, samples + 2 * x, width - x, out);
}
#endif

// The depth remap of `width` pixels (CpuLens::RemapDepthRow before its special pixels):
// `samples` as RemapRowPortable's, `stride` floats a source row.
void RemapDepthRowPortable(const float* source_z, std::size_t stride, const uint32_t* samples,
                           int width, float* z_row) {
  for (int x = 0; x < width; ++x) {
    const std::size_t o = samples[2 * x] / 4;  // the sample's top-left source pixel
    const uint32_t fx = samples[2 * x + 1] & 0xFFFFu, fy = samples[2 * x + 1] >> 16;
    const float z00 = source_z[o], z10 = source_z[o + 1];
    const float z01 = source_z[o + stride], z11 = source_z[o + stride + 1];
    const float low = std::min(std::min(z00, z10), std::min(z01, z11));
    const float high = std::max(std::max(z00, z10), std::max(z01, z11));
    if (low > 0.0f && high - low <= 0.02f * low) {
      const float wx = static_cast<float>(fx) * (1.0f / 256.0f);
      const float wy = static_cast<float>(fy) * (1.0f / 256.0f);
      const float top = z00 + (z10 - z00) * wx, bottom = z01 + (z11 - z01) * wx;
      z_row[x] = top + (bottom - top) * wy;
    } else {
      z_row[x] = source_z[o + (fy >= 128 ? stride : 0) + (fx >= 128 ? 1 : 0)];
    }
  }
}

#if defined(__x86_64__)
// The source values at `base` + the offsets of pixels x and x + 1 and one to the right of
// each: (x's, x's right, x + 1's, x + 1's right), one 8-byte load a pixel.
__attribute__((target("avx2"))) inline __m128 Pairs2(const float* base, const uint32_t* samples,
                                                     int x) {
  const __m128 first = _mm_castsi128_ps(
      _mm_loadl_epi64(reinterpret_cast<const __m128i*>(base + samples[2 * x] / 4)));
  return _mm_loadh_pi(first, reinterpret_cast<const __m64*>(base + samples[2 * x + 2] / 4));
}

// The same, 8 pixels at a time without gathers (slow on some CPUs): each pixel's two source
// pairs (z00, z10) and (z01, z11) with one 8-byte load each, sorted into vectors by shuffles;
// then the portable loop's float operations lane by lane (no "fma": it rounds the product and
// the sum apart), the nearest value chosen among the four by blends. Depths are 0 or positive,
// never NaN, so the vector min and max pick what std::min and std::max pick: the same bits.
__attribute__((target("avx2"))) void RemapDepthRowAvx2(const float* source_z, std::size_t stride,
                                                       const uint32_t* samples, int width,
                                                       float* z_row) {
  const __m256i evens = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
  const __m256i low16 = _mm256_set1_epi32(0xFFFF), half = _mm256_set1_epi32(127);
  const __m256 step = _mm256_set1_ps(0.02f), inv = _mm256_set1_ps(1.0f / 256.0f);
  const __m256 zero = _mm256_setzero_ps();
  const float* below = source_z + stride;
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    // Lanes 0-3 hold pixels x .. x + 3, lanes 4-7 pixels x + 4 .. x + 7 (AVX's two halves).
    const __m256 top_a = _mm256_set_m128(Pairs2(source_z, samples, x + 4),
                                         Pairs2(source_z, samples, x));  // pixels 0, 1 | 4, 5
    const __m256 top_b = _mm256_set_m128(Pairs2(source_z, samples, x + 6),
                                         Pairs2(source_z, samples, x + 2));  // 2, 3 | 6, 7
    const __m256 bottom_a =
        _mm256_set_m128(Pairs2(below, samples, x + 4), Pairs2(below, samples, x));
    const __m256 bottom_b =
        _mm256_set_m128(Pairs2(below, samples, x + 6), Pairs2(below, samples, x + 2));
    const __m256 z00 = _mm256_shuffle_ps(top_a, top_b, _MM_SHUFFLE(2, 0, 2, 0));
    const __m256 z10 = _mm256_shuffle_ps(top_a, top_b, _MM_SHUFFLE(3, 1, 3, 1));
    const __m256 z01 = _mm256_shuffle_ps(bottom_a, bottom_b, _MM_SHUFFLE(2, 0, 2, 0));
    const __m256 z11 = _mm256_shuffle_ps(bottom_a, bottom_b, _MM_SHUFFLE(3, 1, 3, 1));
    // Samples x .. x + 3 and x + 4 .. x + 7: (offset, weights) pairs; their 8 weights.
    const __m256i a = _mm256_permutevar8x32_epi32(
        _mm256_loadu_si256(reinterpret_cast<const __m256i*>(samples + 2 * x)), evens);
    const __m256i b = _mm256_permutevar8x32_epi32(
        _mm256_loadu_si256(reinterpret_cast<const __m256i*>(samples + 2 * x + 8)), evens);
    const __m256i weights = _mm256_permute2x128_si256(a, b, 0x31);
    const __m256i fx = _mm256_and_si256(weights, low16), fy = _mm256_srli_epi32(weights, 16);
    const __m256 low = _mm256_min_ps(_mm256_min_ps(z00, z10), _mm256_min_ps(z01, z11));
    const __m256 high = _mm256_max_ps(_mm256_max_ps(z00, z10), _mm256_max_ps(z01, z11));
    const __m256 smooth = _mm256_and_ps(
        _mm256_cmp_ps(low, zero, _CMP_GT_OQ),
        _mm256_cmp_ps(_mm256_sub_ps(high, low), _mm256_mul_ps(step, low), _CMP_LE_OQ));
    const __m256 wx = _mm256_mul_ps(_mm256_cvtepi32_ps(fx), inv);
    const __m256 wy = _mm256_mul_ps(_mm256_cvtepi32_ps(fy), inv);
    const __m256 top = _mm256_add_ps(z00, _mm256_mul_ps(_mm256_sub_ps(z10, z00), wx));
    const __m256 bottom = _mm256_add_ps(z01, _mm256_mul_ps(_mm256_sub_ps(z11, z01), wx));
    const __m256 blended = _mm256_add_ps(top, _mm256_mul_ps(_mm256_sub_ps(bottom, top), wy));
    const __m256 right = _mm256_castsi256_ps(_mm256_cmpgt_epi32(fx, half));  // fx >= 128
    const __m256 down = _mm256_castsi256_ps(_mm256_cmpgt_epi32(fy, half));   // fy >= 128
    const __m256 nearest = _mm256_blendv_ps(_mm256_blendv_ps(z00, z10, right),
                                            _mm256_blendv_ps(z01, z11, right), down);
    _mm256_storeu_ps(z_row + x, _mm256_blendv_ps(nearest, blended, smooth));
  }
  RemapDepthRowPortable(source_z, stride, samples + 2 * x, width - x, z_row + x);
}
#endif

}  // namespace

CpuLens::CpuLens(const RemapTable& table, int width, int height, int source_width,
                 int source_height)
    : width_(width), height_(height), source_width_(source_width), source_height_(source_height) {
  const std::size_t n = static_cast<std::size_t>(width) * height;
  samples_.resize(n);
  row_first_.reserve(static_cast<std::size_t>(height) + 1);
  for (int v = 0; v < height; ++v) {
    row_first_.push_back(static_cast<uint32_t>(special_pixel_.size()));
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      const float* m = &table.map[4 * i];
      if (m[2] < 0.0f) {  // no ray: black
        samples_[i] = MakeSample(0.0, 0.0);
        special_pixel_.push_back(static_cast<uint32_t>(i));
        special_first_.push_back(static_cast<uint32_t>(special_samples_.size()));
        continue;
      }
      const int taps = static_cast<int>(m[3] + 0.5f);
      const int nu = taps & 15, nv = taps >> 4;
      if (nu * nv == 1) {
        samples_[i] = MakeSample(m[0], m[1]);
        continue;
      }
      // As the pass: samples on a grid over the parallelogram of the steps to the neighbours.
      const float* f = &table.footprint[4 * i];
      special_pixel_.push_back(static_cast<uint32_t>(i));
      special_first_.push_back(static_cast<uint32_t>(special_samples_.size()));
      for (int j = 0; j < nv; ++j) {
        for (int k = 0; k < nu; ++k) {
          const double ox = (k + 0.5) / nu - 0.5, oy = (j + 0.5) / nv - 0.5;
          special_samples_.push_back(
              MakeSample(m[0] + ox * f[0] + oy * f[2], m[1] + ox * f[1] + oy * f[3]));
        }
      }
      samples_[i] = special_samples_[special_first_.back()];
    }
  }
  row_first_.push_back(static_cast<uint32_t>(special_pixel_.size()));
  special_first_.push_back(static_cast<uint32_t>(special_samples_.size()));
}

CpuLens::Sample CpuLens::MakeSample(double x, double y) const {
  // Clamped to the edge, as the pass's sampler: outside the view, the edge pixel's value.
  const auto axis = [](double s, int size, uint32_t* first, uint32_t* weight) {
    s = std::clamp(s, 0.0, static_cast<double>(size - 1));
    double whole = std::floor(s);
    long fraction = std::lround((s - whole) * 256.0);
    if (fraction == 256) {
      whole += 1.0;
      fraction = 0;
    }
    if (whole >= size - 1) {  // the last pixel: the pair ends there, all weight on it
      whole = size - 2;
      fraction = 256;
    }
    *first = static_cast<uint32_t>(whole);
    *weight = static_cast<uint32_t>(fraction);
  };
  uint32_t x0 = 0, y0 = 0, fx = 0, fy = 0;
  axis(x, source_width_, &x0, &fx);
  axis(y, source_height_, &y0, &fy);
  return {4u * (y0 * static_cast<uint32_t>(source_width_) + x0), fx | fy << 16};
}

void CpuLens::RemapRow(const uint8_t* source, int y, uint8_t* rgba_row, bool simd) const {
  const uint32_t stride = 4u * static_cast<uint32_t>(source_width_);
  static_assert(sizeof(Sample) == 2 * sizeof(uint32_t));
  const uint32_t* row =
      reinterpret_cast<const uint32_t*>(samples_.data() + static_cast<std::size_t>(y) * width_);
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && simd) {
    RemapRowAvx2(source, stride, row, width_, rgba_row);
  } else {
    RemapRowPortable(source, stride, row, width_, rgba_row);
  }
#else
  static_cast<void>(simd);
  RemapRowPortable(source, stride, row, width_, rgba_row);
#endif
  for (uint32_t k = row_first_[y]; k < row_first_[y + 1]; ++k) {
    const uint32_t first = special_first_[k], end = special_first_[k + 1];
    uint8_t* out = rgba_row + 4 * (special_pixel_[k] - static_cast<uint32_t>(y) * width_);
    if (first == end) {
      std::memset(out, 0, 4);
      out[3] = 255;
      continue;
    }
    uint32_t sum[4] = {0, 0, 0, 0};
    for (uint32_t s = first; s < end; ++s) {
      Sample4(source, stride, special_samples_[s].offset, special_samples_[s].weights, sum);
    }
    const uint32_t n = end - first;
    for (int c = 0; c < 4; ++c) {
      out[c] = static_cast<uint8_t>((sum[c] + n * 32768u) / (n * 65536u));
    }
  }
}

void CpuLens::RemapDepthRow(const float* source_z, int y, float* z_row, bool simd) const {
  const uint32_t* row =
      reinterpret_cast<const uint32_t*>(samples_.data() + static_cast<std::size_t>(y) * width_);
  const std::size_t stride = static_cast<std::size_t>(source_width_);
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && simd) {
    RemapDepthRowAvx2(source_z, stride, row, width_, z_row);
  } else {
    RemapDepthRowPortable(source_z, stride, row, width_, z_row);
  }
#else
  static_cast<void>(simd);
  RemapDepthRowPortable(source_z, stride, row, width_, z_row);
#endif
  for (uint32_t k = row_first_[y]; k < row_first_[y + 1]; ++k) {
    if (special_first_[k] == special_first_[k + 1]) {
      z_row[special_pixel_[k] - static_cast<uint32_t>(y) * width_] = 0.0f;
    }
  }
}

}  // namespace saccade::render::gl
