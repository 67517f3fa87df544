#pragma once
// Pinhole intrinsics of a camera, in OpenCV's conventions.
//
// Conventions (DESIGN.md), stated once here for the whole camera model:
// - Camera optical frame C: x right, y down, z forward (OpenCV's). Units: metres.
// - Image: origin at the top-left, row 0 at the top, u to the right, v down; pixel centres
//   at integer coordinates, so the image spans [-0.5, width - 0.5] x [-0.5, height - 0.5].
// - Normalized (undistorted) coordinates of a point p_C with z > 0: (x, y) = (X/Z, Y/Z).
//   The distortion model maps them to distorted normalized coordinates (xd, yd), and
//     u = fx * xd + skew * yd + cx,   v = fy * yd + cy.
//   With skew = 0 this is exactly cv::projectPoints; OpenCV's fisheye model writes the same
//   skew as alpha = skew / fx.

#include <Eigen/Core>

namespace saccade::geometry {

/// Image size and the calibrated matrix K = [fx skew cx; 0 fy cy; 0 0 1], in pixels.
class Intrinsics {
 public:
  /// Throws InvalidArgument naming the field and the value when width or height is not
  /// positive, fx or fy is not a positive finite number, or cx, cy, skew is not finite.
  Intrinsics(int width, int height, double fx, double fy, double cx, double cy, double skew = 0.0);

  /// From a 3x3 upper-triangular K with K(2,2) = 1 (same checks; throws on another K).
  static Intrinsics FromMatrix(const Eigen::Matrix3d& K, int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  double skew() const { return skew_; }

  /// The 3x3 camera matrix K.
  Eigen::Matrix3d Matrix() const;

  /// Distorted normalized coordinates (xd, yd) to pixel (u, v).
  Eigen::Vector2d NormalizedToPixel(const Eigen::Vector2d& xd) const;
  /// Pixel (u, v) to distorted normalized coordinates (xd, yd); inverse of NormalizedToPixel.
  Eigen::Vector2d PixelToNormalized(const Eigen::Vector2d& uv) const;

  /// Horizontal and vertical field of view of the pinhole (no distortion), in radians,
  /// measured across the image edges (-0.5 and width - 0.5) with the principal point as it is.
  double HorizontalFov() const;
  double VerticalFov() const;

  bool operator==(const Intrinsics&) const = default;

 private:
  int width_;
  int height_;
  double fx_;
  double fy_;
  double cx_;
  double cy_;
  double skew_;
};

}  // namespace saccade::geometry
