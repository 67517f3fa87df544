#include "render/gl/internal_color_depth.h"

#include <cstddef>

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

void CameraZRows(const ColorDepthMap& map, const float* window_depth, int first_row, int end_row,
                 float* camera_z) {
  const std::size_t width = map.column.size();
  // In double: near the far plane 2 d - 1 + a is a small difference of numbers near 1.
  const double a_minus_1 = map.a - 1.0, b = map.b;
  for (int v = first_row; v < end_row; ++v) {
    const float* d = window_depth + static_cast<std::size_t>(v) * width;
    float* z = camera_z + static_cast<std::size_t>(v) * width;
    const float r = map.row[v];
    for (std::size_t u = 0; u < width; ++u) {
      const double D = b / (2.0 * d[u] + a_minus_1);
      z[u] = d[u] < 1.0f ? static_cast<float>(D) * (map.column[u] + r) : 0.0f;
    }
  }
}

}  // namespace saccade::render::gl
