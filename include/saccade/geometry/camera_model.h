#pragma once
// A calibrated camera: intrinsics plus lens distortion (conventions in intrinsics.h).

#include <Eigen/Core>
#include <optional>

#include "saccade/geometry/distortion.h"
#include "saccade/geometry/intrinsics.h"

namespace saccade::geometry {

/// Intrinsics and distortion together: projects points to pixels and pixels to rays.
/// A small copyable value; all methods are const and thread-safe; none throws.
class CameraModel {
 public:
  CameraModel(const Intrinsics& intrinsics, const Distortion& distortion = Distortion())
      : intrinsics_(intrinsics), distortion_(distortion) {}

  const Intrinsics& intrinsics() const { return intrinsics_; }
  const Distortion& distortion() const { return distortion_; }

  /// Pixel of a point p_C in the camera optical frame (metres), as cv::projectPoints or
  /// cv::fisheye::projectPoints. std::nullopt when the model cannot image the point (behind a
  /// pinhole or radtan camera, or at the centre of projection). The pixel may lie outside the
  /// image: callers test with Contains().
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_C) const;

  /// Unit ray in the camera frame through pixel (u, v), distortion removed. std::nullopt when
  /// the undistortion does not converge (outside the invertible region of the model).
  std::optional<Eigen::Vector3d> Unproject(const Eigen::Vector2d& uv) const;

  /// Distorted pixel of an undistorted (ideal pinhole) pixel with the same K, and back.
  /// These are what cv::undistortPoints(..., P = K) and its inverse compute.
  Eigen::Vector2d DistortPixel(const Eigen::Vector2d& uv_undistorted) const;
  /// Reports non-convergence instead of a silent wrong answer; the point is in pixels.
  UndistortResult UndistortPixel(const Eigen::Vector2d& uv_distorted) const;

  /// True when (u, v) lies inside the image, [-0.5, width - 0.5) x [-0.5, height - 0.5).
  bool Contains(const Eigen::Vector2d& uv) const;

  bool operator==(const CameraModel&) const = default;

 private:
  Intrinsics intrinsics_;
  Distortion distortion_;
};

}  // namespace saccade::geometry
