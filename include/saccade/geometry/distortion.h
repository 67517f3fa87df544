#pragma once
// Lens distortion models, OpenCV-compatible to the digit (see intrinsics.h for conventions).
//
// - kNone: pinhole, (xd, yd) = (x, y).
// - kRadialTangential: cv::projectPoints' rational model with coefficients in OpenCV's order
//   (k1, k2, p1, p2[, k3[, k4, k5, k6]]):
//     r2 = x^2 + y^2,  c = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
//     xd = x c + 2 p1 x y + p2 (r2 + 2 x^2),   yd = y c + p1 (r2 + 2 y^2) + 2 p2 x y
// - kFisheye: Kannala-Brandt as cv::fisheye::projectPoints, coefficients (k1, k2, k3, k4):
//     theta = angle between the ray and the optical axis (atan2(sqrt(X^2 + Y^2), Z), so rays
//     beyond 90 degrees are valid), theta_d = theta (1 + k1 t^2 + k2 t^4 + k3 t^6 + k4 t^8),
//     (xd, yd) = theta_d / r * (X, Y) / Z with r = sqrt(X^2 + Y^2) / Z  (theta_d * unit
//     direction of (X, Y) for rays at or beyond 90 degrees).

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

namespace saccade::geometry {

enum class DistortionModel { kNone, kRadialTangential, kFisheye };

/// "none", "radtan" or "fisheye".
std::string ToString(DistortionModel model);

/// Result of an iterative inversion: never a silent wrong answer.
struct UndistortResult {
  Eigen::Vector2d point = Eigen::Vector2d::Zero();  ///< best estimate found
  bool converged = false;  ///< true when |distort(point) - input| <= tolerance
  int iterations = 0;
  double residual = 0.0;  ///< |distort(point) - input| in normalized units
};

/// A distortion model and its coefficients. A small copyable value.
class Distortion {
 public:
  /// No distortion.
  Distortion() = default;

  /// Radial-tangential: 4, 5 or 8 coefficients in OpenCV's order (k1 k2 p1 p2 [k3 [k4 k5 k6]]).
  /// 12 or 14 (thin prism, tilt) are accepted when those extra terms are zero.
  /// Throws InvalidArgument on another count, a non-finite value or non-zero extra terms.
  static Distortion RadialTangential(std::span<const double> coefficients);
  /// Kannala-Brandt fisheye: exactly 4 coefficients (k1 k2 k3 k4). Throws InvalidArgument.
  static Distortion Fisheye(std::span<const double> coefficients);
  /// Dispatch on the model; kNone accepts an empty list or all zeros.
  static Distortion FromCoefficients(DistortionModel model, std::span<const double> coefficients);

  DistortionModel model() const { return model_; }
  /// The coefficients in OpenCV's order: radtan always 8 (k1 k2 p1 p2 k3 k4 k5 k6), fisheye 4,
  /// none 0.
  const std::vector<double>& coefficients() const { return coefficients_; }
  /// True for kNone and for any model whose coefficients are all zero and (radtan) maps
  /// (x, y) to itself. A zero fisheye is NOT the identity: it is the equidistant projection.
  bool IsIdentity() const;

  /// Distorted normalized coordinates of a ray in the camera frame (any length, z may be <= 0
  /// for kFisheye). Returns false when the ray cannot be imaged by this model (z <= 0 for kNone
  /// and kRadialTangential, the zero vector for all).
  bool DistortRay(const Eigen::Vector3d& ray_C, Eigen::Vector2d* xd) const;
  /// Distorted normalized coordinates of undistorted normalized coordinates (x, y) = (X/Z, Y/Z).
  Eigen::Vector2d Distort(const Eigen::Vector2d& xy) const;
  /// 2x2 Jacobian of Distort at xy.
  Eigen::Matrix2d DistortJacobian(const Eigen::Vector2d& xy) const;

  /// Inverse of Distort by Newton iteration from (xd, yd), to `tolerance` in normalized units.
  /// Reports non-convergence in the result rather than returning a wrong point silently.
  UndistortResult Undistort(const Eigen::Vector2d& xd, double tolerance = 1e-14,
                            int max_iterations = 100) const;
  /// Inverse of DistortRay: a unit ray in the camera frame for distorted normalized
  /// coordinates. For kFisheye the ray may point beyond 90 degrees from the optical axis.
  /// Returns false (and leaves *ray_C unspecified) when the inversion does not converge.
  bool UndistortToRay(const Eigen::Vector2d& xd, Eigen::Vector3d* ray_C,
                      double tolerance = 1e-14) const;

  bool operator==(const Distortion&) const = default;

 private:
  DistortionModel model_ = DistortionModel::kNone;
  std::vector<double> coefficients_;
};

}  // namespace saccade::geometry
