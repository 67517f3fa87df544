#include "render/gl/internal_color_depth.h"

#include <cstddef>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace saccade::render::gl {

ColorDepthMap MakeColorDepthMap(const Eigen::Matrix4d& projection, const Eigen::Matrix3d& R_CV,
                                const geometry::Intrinsics& source) {
  ColorDepthMap map;
  map.a = projection(2, 2);
  map.b = projection(2, 3);
  map.column.resize(static_cast<std::size_t>(source.width()));
  for (int u = 0; u < source.width(); ++u) {
    map.column[u] = static_cast<float>(R_CV(2, 0) * (u - source.cx()) / source.fx());
  }
  map.row.resize(static_cast<std::size_t>(source.height()));
  for (int v = 0; v < source.height(); ++v) {
    map.row[v] = static_cast<float>(R_CV(2, 1) * (v - source.cy()) / source.fy() + R_CV(2, 2));
  }
  return map;
}

namespace {

#if defined(__x86_64__)
// Pixels [0, n - n % 4) of a row, four at a time: D in double (2 d, + (a - 1), b / that), then
// z in float, masked to 0 where d >= 1 (or d is NaN), as the loop below. Returns the pixels done.
__attribute__((target("avx"))) std::size_t CameraZRowAvx(const float* d, const float* column,
                                                         float r, double a_minus_1, double b,
                                                         std::size_t n, float* z) {
  const __m256d two = _mm256_set1_pd(2.0), offset = _mm256_set1_pd(a_minus_1),
                numerator = _mm256_set1_pd(b);
  const __m128 one = _mm_set1_ps(1.0f), row = _mm_set1_ps(r);
  std::size_t u = 0;
  for (; u + 4 <= n; u += 4) {
    const __m128 depth = _mm_loadu_ps(d + u);
    const __m256d D =
        _mm256_div_pd(numerator, _mm256_add_pd(_mm256_mul_pd(two, _mm256_cvtps_pd(depth)), offset));
    const __m128 value = _mm_mul_ps(_mm256_cvtpd_ps(D), _mm_add_ps(_mm_loadu_ps(column + u), row));
    _mm_storeu_ps(z + u, _mm_and_ps(value, _mm_cmplt_ps(depth, one)));
  }
  return u;
}
#endif

}  // namespace

void CameraZRows(const ColorDepthMap& map, const float* window_depth, int first_row, int end_row,
                 float* camera_z, bool simd) {
  const std::size_t width = map.column.size();
  const float* column = map.column.data();
  // In double: near the far plane 2 d - 1 + a is a small difference of numbers near 1.
  const double a_minus_1 = map.a - 1.0, b = map.b;
#if defined(__x86_64__)
  static const bool avx = __builtin_cpu_supports("avx");  // asked once
  const bool vectors = avx && simd;
#else
  static_cast<void>(simd);
  const bool vectors = false;
#endif
  for (int v = first_row; v < end_row; ++v) {
    const float* d = window_depth + static_cast<std::size_t>(v) * width;
    float* z = camera_z + static_cast<std::size_t>(v) * width;
    const float r = map.row[v];
    std::size_t u = 0;
#if defined(__x86_64__)
    if (vectors) u = CameraZRowAvx(d, column, r, a_minus_1, b, width, z);
#endif
    for (; u < width; ++u) {
      const double D = b / (2.0 * d[u] + a_minus_1);
      z[u] = d[u] < 1.0f ? static_cast<float>(D) * (column[u] + r) : 0.0f;
    }
  }
}

}  // namespace saccade::render::gl
