#include "saccade/geometry/gl_projection.h"

#include <fmt/format.h>

#include <cmath>
#include <string_view>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

void CheckClipPlanes(std::string_view where, const ClipPlanes& clip) {
  if (!(std::isfinite(clip.near) && std::isfinite(clip.far) && clip.near > 0.0 &&
        clip.near < clip.far)) {
    throw InvalidArgument(
        fmt::format("{}: clip planes must satisfy 0 < near < far < inf, got near = {}, far = {}",
                    where, clip.near, clip.far));
  }
}

}  // namespace

// The matrix of gl_projection.h. Derivation: p_eye = (X, -Y, -Z), so w_clip = Z and
//   x_ndc = (2 (fx x + s y) + 2 cx + 1 - w) / w = (2 u + 1 - w) / w,
//   y_ndc = (h - 2 fy y - 2 cy - 1) / h       = (h - 2 v - 1) / h,
// with (x, y) = (X/Z, Y/Z); the viewport maps them to x_window = (x_ndc + 1) w / 2 = u + 0.5
// and y_window = (y_ndc + 1) h / 2 = h - v - 0.5. Depth: z_eye = -near -> -1, -far -> +1.
Eigen::Matrix4d GlProjectionFromIntrinsics(const Intrinsics& intrinsics, const ClipPlanes& clip,
                                           bool flip_rows) {
  CheckClipPlanes("GlProjectionFromIntrinsics", clip);
  const double w = intrinsics.width(), h = intrinsics.height();
  const double n = clip.near, f = clip.far;
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = 2.0 * intrinsics.fx() / w;
  P(0, 1) = -2.0 * intrinsics.skew() / w;
  P(0, 2) = (w - 2.0 * intrinsics.cx() - 1.0) / w;
  P(1, 1) = 2.0 * intrinsics.fy() / h;
  P(1, 2) = (2.0 * intrinsics.cy() + 1.0 - h) / h;
  P(2, 2) = -(f + n) / (f - n);
  P(2, 3) = -2.0 * f * n / (f - n);
  P(3, 2) = -1.0;
  if (flip_rows) P.row(1) = -P.row(1);
  return P;
}

Intrinsics IntrinsicsFromGlProjection(const Eigen::Matrix4d& projection, int width, int height,
                                      bool flip_rows) {
  constexpr std::string_view kWhere = "IntrinsicsFromGlProjection";
  if (width <= 0 || height <= 0) {
    throw InvalidArgument(
        fmt::format("{}: viewport width and height must be positive numbers of pixels, got {} x {}",
                    kWhere, width, height));
  }
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      if (!std::isfinite(projection(row, col))) {
        throw InvalidArgument(fmt::format("{}: P({},{}) must be finite, got {}", kWhere, row, col,
                                          projection(row, col)));
      }
    }
  }
  Eigen::Matrix4d P = projection;
  if (flip_rows) P.row(1) = -P.row(1);
  // Entries fixed by the form of the matrix; exact, since GlProjectionFromIntrinsics writes
  // them exactly and a matrix that differs there is another kind of projection.
  struct Fixed {
    int row, col;
    double value;
  };
  for (const Fixed& e :
       {Fixed{0, 3, 0.0}, Fixed{1, 0, 0.0}, Fixed{1, 3, 0.0}, Fixed{2, 0, 0.0}, Fixed{2, 1, 0.0},
        Fixed{3, 0, 0.0}, Fixed{3, 1, 0.0}, Fixed{3, 2, -1.0}, Fixed{3, 3, 0.0}}) {
    const double got = projection(e.row, e.col) * (flip_rows && e.row == 1 ? -1.0 : 1.0);
    if (got != e.value) {
      throw InvalidArgument(fmt::format(
          "{}: P({},{}) must be {} for a perspective projection made from K{}, got {}", kWhere,
          e.row, e.col, e.value, flip_rows ? " (flip_rows: after negating row 1)" : "",
          projection(e.row, e.col)));
    }
  }
  if (!(P(0, 0) > 0.0)) {
    throw InvalidArgument(
        fmt::format("{}: P(0,0) = 2 fx / width must be positive, got {}", kWhere, P(0, 0)));
  }
  if (!(P(1, 1) > 0.0)) {
    throw InvalidArgument(
        fmt::format("{}: P(1,1) = 2 fy / height must be {}, got {}{}", kWhere,
                    flip_rows ? "negative (flip_rows)" : "positive", projection(1, 1),
                    P(1, 1) < 0.0 ? " (was flip_rows set as when the matrix was made?)" : ""));
  }
  const double w = width, h = height;
  const double fx = 0.5 * P(0, 0) * w;
  const double fy = 0.5 * P(1, 1) * h;
  const double skew = -0.5 * P(0, 1) * w;
  const double cx = 0.5 * (w - 1.0 - P(0, 2) * w);
  const double cy = 0.5 * (P(1, 2) * h + h - 1.0);
  return Intrinsics(width, height, fx, fy, cx, cy, skew);
}

ClipPlanes ClipPlanesFromGlProjection(const Eigen::Matrix4d& projection) {
  // P(2,2) = -(f + n) / (f - n) = A, P(2,3) = -2 f n / (f - n) = B:
  // n = B / (A - 1), f = B / (A + 1).
  const double A = projection(2, 2), B = projection(2, 3);
  ClipPlanes clip;
  clip.near = B / (A - 1.0);
  clip.far = B / (A + 1.0);
  if (!(std::isfinite(clip.near) && std::isfinite(clip.far) && clip.near > 0.0 &&
        clip.near < clip.far)) {
    throw InvalidArgument(fmt::format(
        "ClipPlanesFromGlProjection: P(2,2) = {} and P(2,3) = {} give near = {}, far = {}; "
        "expected 0 < near < far < inf",
        A, B, clip.near, clip.far));
  }
  return clip;
}

Eigen::Matrix3d OpticalToGlEye() { return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal(); }

Eigen::Vector2d WindowToPixel(const Eigen::Vector2d& window, int height) {
  return {window.x() - 0.5, height - window.y() - 0.5};
}

Eigen::Vector2d PixelToWindow(const Eigen::Vector2d& pixel, int height) {
  return {pixel.x() + 0.5, height - pixel.y() - 0.5};
}

}  // namespace saccade::geometry
