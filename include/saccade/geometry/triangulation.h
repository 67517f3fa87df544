#pragma once
// Triangulation of a 3D point from two rays (seed section 4.2).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace saccade::geometry {

/// A ray in some frame F: origin (metres) and unit direction.
struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};

/// Outcome of a triangulation.
struct TriangulationResult {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< estimate, in the rays' frame
  double gap = 0.0;          ///< length of the shortest segment between the rays (metres)
  double ray_param_a = 0.0;  ///< distance along ray a to its closest point (metres)
  double ray_param_b = 0.0;  ///< distance along ray b to its closest point (metres)
  bool parallel = false;     ///< rays (nearly) parallel: no point, `point` is meaningless
  bool behind = false;       ///< the closest points lie behind a ray origin
  bool ok() const { return !parallel && !behind; }
};

/// Midpoint of the shortest segment between two rays (seed section 4.2). Rays whose
/// directions make an angle below `min_angle` radians are reported parallel, never divided
/// by zero.
TriangulationResult TriangulateMidpoint(const Ray& a, const Ray& b, double min_angle = 1e-9);

/// Linear (DLT) triangulation from two views: each view is the 3x4 matrix [R | t] of
/// the world-to-camera transform (p_C = R p_W + t) and the observation in normalized
/// (undistorted) coordinates. Solved with an SVD; `gap` is the midpoint gap of the same rays.
TriangulationResult TriangulateDlt(const Eigen::Matrix<double, 3, 4>& view_a,
                                   const Eigen::Vector2d& xy_a,
                                   const Eigen::Matrix<double, 3, 4>& view_b,
                                   const Eigen::Vector2d& xy_b);

}  // namespace saccade::geometry
