// The lens mesh (render/gl/internal_effects.h, LensMesh): the cells cover every pixel of the
// camera once; where they are linear, the position the rasterizer interpolates is within the
// tolerance of the lens map's at every pixel centre, one view, one sample; everything else
// (a cube's face edges, the pixels with no ray or several samples) is drawn through the map.
// The end-to-end proof is tests/render/marker_accuracy_test.cc (markers against OpenCV).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "render/gl/internal_effects.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/lens_map.h"

namespace saccade::render::gl {
namespace {

struct Coverage {
  std::vector<int> count;           // cells over each pixel
  std::vector<int> kind;            // 1 linear, 2 exact (of the last cell over it)
  double max_error = 0.0;           // over the linear cells' pixels, recomputed here
  double max_residual_error = 0.0;  // and with the residual added back
  int64_t linear_pixels = 0;
};

// Reads the cells back from the vertices (NDC to pixel edges) and, for the linear ones,
// interpolates each pixel centre's position over the cell's two triangles.
Coverage Cover(const LensMesh& mesh, const RemapTable& table, int width, int height,
               double tolerance = kLensMeshTolerancePx) {
  EXPECT_EQ(mesh.residual.size(), 2u * width * height);
  Coverage c;
  c.count.assign(static_cast<std::size_t>(width) * height, 0);
  c.kind.assign(c.count.size(), 0);
  const auto cells = [&](const std::vector<uint32_t>& indices, int kind) {
    EXPECT_EQ(indices.size() % 6, 0u);
    for (std::size_t i = 0; i + 5 < indices.size(); i += 6) {
      // Triangles (00, 10, 11), (00, 11, 01) of the corners first + 0..3.
      const uint32_t first = indices[i];
      ASSERT_EQ(indices[i + 1], first + 1);
      ASSERT_EQ(indices[i + 2], first + 3);
      const auto corner = [&](uint32_t k) { return &mesh.vertices[5 * (first + k)]; };
      const double x0 = std::lround((corner(0)[0] + 1.0) * 0.5 * width);
      const double y0 = std::lround((corner(0)[1] + 1.0) * 0.5 * height);
      const double x1 = std::lround((corner(3)[0] + 1.0) * 0.5 * width);
      const double y1 = std::lround((corner(3)[1] + 1.0) * 0.5 * height);
      ASSERT_LT(x0, x1);
      ASSERT_LT(y0, y1);
      for (int v = static_cast<int>(y0); v < y1; ++v) {
        for (int u = static_cast<int>(x0); u < x1; ++u) {
          const std::size_t p = static_cast<std::size_t>(v) * width + u;
          ++c.count[p];
          c.kind[p] = kind;
          const Eigen::Vector2d residual(mesh.residual[2 * p], mesh.residual[2 * p + 1]);
          if (kind != 1) {
            EXPECT_EQ(residual.norm(), 0.0) << "a residual in an exact cell, at " << u << ", " << v;
            continue;
          }
          ++c.linear_pixels;
          const float* m = &table.map[4 * p];
          EXPECT_EQ(m[3], 17.0f) << "a pixel of several samples in a linear cell, at " << u << ", "
                                 << v;
          const double s = (u + 0.5 - x0) / (x1 - x0), t = (v + 0.5 - y0) / (y1 - y0);
          const auto at = [&](uint32_t k) {
            return Eigen::Vector3d(corner(k)[2], corner(k)[3], corner(k)[4]);
          };
          const Eigen::Vector3d q = s >= t ? at(0) + s * (at(1) - at(0)) + t * (at(3) - at(1))
                                           : at(0) + s * (at(3) - at(2)) + t * (at(2) - at(0));
          EXPECT_EQ(q.z(), m[2]) << "the cell's view is not the pixel's, at " << u << ", " << v;
          const double e = (q.head<2>() - Eigen::Vector2d(m[0], m[1])).norm();
          c.max_error = std::max(c.max_error, e);
          const Eigen::Vector2d corrected = q.head<2>() + (tolerance / 127.0) * residual;
          c.max_residual_error =
              std::max(c.max_residual_error, (corrected - Eigen::Vector2d(m[0], m[1])).norm());
        }
      }
    }
  };
  cells(mesh.linear, 1);
  cells(mesh.exact, 2);
  return c;
}

geometry::CameraModel Camera(int width, int height, double f, const std::string& model,
                             const std::vector<double>& coefficients) {
  const geometry::Intrinsics K(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0);
  if (model == "fisheye") {
    return geometry::CameraModel(K, geometry::Distortion::Fisheye(coefficients));
  }
  return geometry::CameraModel(K, geometry::Distortion::RadialTangential(coefficients));
}

TEST(LensMeshTest, TheBenchLensIsAllLinearCellsWithinTheTolerance) {
  // scenes/bench.yaml's eyes: 6 mm on 4.65 um pixels, barrel distortion.
  const geometry::LensMap lens = geometry::MakeLensMap(
      Camera(1024, 768, 1290.32, "radtan", {-0.2, 0.1, 0.0005, -0.0003, 0.0}));
  const RemapTable table = MakeRemapTable(lens);
  const LensMesh mesh = MakeLensMesh(table, lens.width, lens.height);
  const Coverage c = Cover(mesh, table, lens.width, lens.height);
  for (std::size_t p = 0; p < c.count.size(); ++p) {
    ASSERT_EQ(c.count[p], 1) << "pixel " << p % lens.width << ", " << p / lens.width;
  }
  EXPECT_EQ(c.linear_pixels, int64_t{1024} * 768);
  EXPECT_EQ(mesh.linear_pixels, c.linear_pixels);
  EXPECT_TRUE(mesh.exact.empty());
  EXPECT_LE(c.max_error, kLensMeshTolerancePx);
  EXPECT_NEAR(mesh.max_error_px, c.max_error, 1e-6);
  // With the residual added back, every pixel is within half a code of the map on each axis
  // (tolerance / 254, 0.002 px), within the 0.01 px the mesh alone was held to before.
  EXPECT_LE(c.max_residual_error, std::sqrt(2.0) * kLensMeshTolerancePx / 254.0 + 1e-5);
  EXPECT_NEAR(mesh.max_residual_error_px, c.max_residual_error, 1e-5);
  EXPECT_GT(c.max_error, 10.0 * c.max_residual_error);
  // Cells as large as the tolerance lets them be: far fewer than the 4 x 4 floor would give.
  EXPECT_LT(mesh.linear.size() / 6, 1024u * 768u / 64u);
}

TEST(LensMeshTest, AFisheyeCubeDrawsItsRimAndSeveralSamplePixelsThroughTheMap) {
  // 190 degrees across: five cube faces, a rim with no ray, pixels of several samples.
  const geometry::LensMap lens =
      geometry::MakeLensMap(Camera(800, 800, 240, "fisheye", {0.01, -0.004, 0.0005, -0.0001}));
  ASSERT_EQ(lens.kind, geometry::LensMap::Kind::kCube);
  const RemapTable table = MakeRemapTable(lens);
  ASSERT_GT(table.multi_tap_pixels, 0);
  const LensMesh mesh = MakeLensMesh(table, lens.width, lens.height);
  const Coverage c = Cover(mesh, table, lens.width, lens.height);
  int64_t no_ray = 0, several = 0;
  for (std::size_t p = 0; p < c.count.size(); ++p) {
    ASSERT_EQ(c.count[p], 1) << "pixel " << p % lens.width << ", " << p / lens.width;
    const float* m = &table.map[4 * p];
    if (m[2] < 0.0f) {
      ++no_ray;
      EXPECT_EQ(c.kind[p], 2);
    } else if (m[3] != 17.0f) {
      ++several;
      EXPECT_EQ(c.kind[p], 2);
    }
  }
  EXPECT_GT(no_ray, 0);
  EXPECT_GT(several, 0);
  // The cube's faces are finer than the camera's pixels almost everywhere (a pixel takes
  // several samples of its footprint), so this lens is drawn through the map, as before the mesh.
  EXPECT_FALSE(mesh.exact.empty());
  EXPECT_EQ(c.linear_pixels, mesh.linear_pixels);
  EXPECT_LE(c.max_error, kLensMeshTolerancePx);
}

TEST(LensMeshTest, AToleranceOfZeroLeavesOnlyCellsTheMapItselfDraws) {
  const geometry::LensMap lens =
      geometry::MakeLensMap(Camera(320, 240, 250, "radtan", {-0.3, 0.1, 0, 0, 0}));
  const RemapTable table = MakeRemapTable(lens);
  const LensMesh exact = MakeLensMesh(table, lens.width, lens.height, 0.0);
  const LensMesh loose = MakeLensMesh(table, lens.width, lens.height, 0.05);
  const Coverage c = Cover(exact, table, lens.width, lens.height, 0.0);
  for (const int n : c.count) ASSERT_EQ(n, 1);
  EXPECT_LT(exact.linear_pixels, int64_t{320} * 240 / 10);  // a curved map is not linear
  EXPECT_GT(loose.linear_pixels, exact.linear_pixels);
  EXPECT_LT(loose.linear.size() + loose.exact.size(), exact.linear.size() + exact.exact.size());
}

}  // namespace
}  // namespace saccade::render::gl
