#include "saccade/geometry/intrinsics.h"

#include <fmt/format.h>

#include <cmath>
#include <string_view>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

// Checks every field; `where` is the public function the user called, so that the message
// starts with it (STYLE.md).
void Validate(std::string_view where, int width, int height, double fx, double fy, double cx,
              double cy, double skew) {
  if (width <= 0) {
    throw InvalidArgument(
        fmt::format("{}: width must be a positive number of pixels, got {}", where, width));
  }
  if (height <= 0) {
    throw InvalidArgument(
        fmt::format("{}: height must be a positive number of pixels, got {}", where, height));
  }
  if (!(std::isfinite(fx) && fx > 0.0)) {
    throw InvalidArgument(
        fmt::format("{}: fx must be a positive finite number, got {}", where, fx));
  }
  if (!(std::isfinite(fy) && fy > 0.0)) {
    throw InvalidArgument(
        fmt::format("{}: fy must be a positive finite number, got {}", where, fy));
  }
  if (!std::isfinite(cx)) {
    throw InvalidArgument(fmt::format("{}: cx must be a finite number, got {}", where, cx));
  }
  if (!std::isfinite(cy)) {
    throw InvalidArgument(fmt::format("{}: cy must be a finite number, got {}", where, cy));
  }
  if (!std::isfinite(skew)) {
    throw InvalidArgument(fmt::format("{}: skew must be a finite number, got {}", where, skew));
  }
}

}  // namespace

Intrinsics::Intrinsics(int width, int height, double fx, double fy, double cx, double cy,
                       double skew)
    : width_(width), height_(height), fx_(fx), fy_(fy), cx_(cx), cy_(cy), skew_(skew) {
  Validate("Intrinsics", width, height, fx, fy, cx, cy, skew);
}

Intrinsics Intrinsics::FromMatrix(const Eigen::Matrix3d& K, int width, int height) {
  constexpr std::string_view kWhere = "Intrinsics::FromMatrix";
  // K must be exactly upper triangular with K(2,2) = 1: a scaled or general 3x3 matrix is
  // another camera, not a rounding of this one.
  struct Fixed {
    int row, col;
    double value;
  };
  for (const Fixed& f : {Fixed{1, 0, 0.0}, Fixed{2, 0, 0.0}, Fixed{2, 1, 0.0}, Fixed{2, 2, 1.0}}) {
    const double got = K(f.row, f.col);
    if (got != f.value) {
      throw InvalidArgument(
          fmt::format("{}: K({},{}) must be {} (upper-triangular K with "
                      "K(2,2) = 1), got {}",
                      kWhere, f.row, f.col, f.value, got));
    }
  }
  Validate(kWhere, width, height, K(0, 0), K(1, 1), K(0, 2), K(1, 2), K(0, 1));
  return Intrinsics(width, height, K(0, 0), K(1, 1), K(0, 2), K(1, 2), K(0, 1));
}

Eigen::Matrix3d Intrinsics::Matrix() const {
  Eigen::Matrix3d K;
  K << fx_, skew_, cx_, 0.0, fy_, cy_, 0.0, 0.0, 1.0;
  return K;
}

Eigen::Vector2d Intrinsics::NormalizedToPixel(const Eigen::Vector2d& xd) const {
  // Same operation order as cv::projectPoints (xd * fx + cx) when skew is zero.
  return {xd.x() * fx_ + skew_ * xd.y() + cx_, xd.y() * fy_ + cy_};
}

Eigen::Vector2d Intrinsics::PixelToNormalized(const Eigen::Vector2d& uv) const {
  const double yd = (uv.y() - cy_) / fy_;
  const double xd = (uv.x() - cx_ - skew_ * yd) / fx_;
  return {xd, yd};
}

double Intrinsics::HorizontalFov() const {
  // Angles of the left and right image edges on the principal row (where skew plays no part).
  return std::atan((cx_ + 0.5) / fx_) + std::atan((width_ - 0.5 - cx_) / fx_);
}

double Intrinsics::VerticalFov() const {
  return std::atan((cy_ + 0.5) / fy_) + std::atan((height_ - 0.5 - cy_) / fy_);
}

}  // namespace saccade::geometry
