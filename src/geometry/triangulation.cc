#include "saccade/geometry/triangulation.h"

#include <Eigen/SVD>
#include <cmath>

namespace saccade::geometry {

TriangulationResult TriangulateMidpoint(const Ray& a, const Ray& b, double min_angle) {
  // Closest points o_a + s d_a and o_b + t d_b: the segment between them is perpendicular to
  // both directions (seed section 4.2, after Schneider & Eberly's segment-segment distance).
  TriangulationResult result;
  const Eigen::Vector3d da = a.direction.normalized();
  const Eigen::Vector3d db = b.direction.normalized();
  const Eigen::Vector3d w0 = a.origin - b.origin;
  const double cos_ab = da.dot(db);
  const double sin_ab = da.cross(db).norm();
  if (!(sin_ab >= std::sin(min_angle))) {  // also catches NaN directions
    result.parallel = true;
    result.gap = (w0 - w0.dot(da) * da).norm();
    return result;
  }
  const double d = da.dot(w0);
  const double e = db.dot(w0);
  const double denominator = sin_ab * sin_ab;  // = 1 - cos_ab^2, without the cancellation
  const double s = (cos_ab * e - d) / denominator;
  const double t = (e - cos_ab * d) / denominator;
  const Eigen::Vector3d pa = a.origin + s * da;
  const Eigen::Vector3d pb = b.origin + t * db;
  result.point = 0.5 * (pa + pb);
  result.gap = (pa - pb).norm();
  result.ray_param_a = s;
  result.ray_param_b = t;
  result.behind = s < 0.0 || t < 0.0;
  return result;
}

TriangulationResult TriangulateDlt(const Eigen::Matrix<double, 3, 4>& view_a,
                                   const Eigen::Vector2d& xy_a,
                                   const Eigen::Matrix<double, 3, 4>& view_b,
                                   const Eigen::Vector2d& xy_b) {
  // Hartley & Zisserman, Multiple View Geometry, section 12.2: x (P3 X) - P1 X = 0 and
  // y (P3 X) - P2 X = 0 for each view; X is the right singular vector of the smallest value.
  Eigen::Matrix4d A;
  A.row(0) = xy_a.x() * view_a.row(2) - view_a.row(0);
  A.row(1) = xy_a.y() * view_a.row(2) - view_a.row(1);
  A.row(2) = xy_b.x() * view_b.row(2) - view_b.row(0);
  A.row(3) = xy_b.y() * view_b.row(2) - view_b.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);

  // The rays of both views, for the gap and the parallel/behind flags.
  auto ray = [](const Eigen::Matrix<double, 3, 4>& view, const Eigen::Vector2d& xy) {
    const Eigen::Matrix3d R = view.leftCols<3>();
    return Ray{-R.transpose() * view.col(3), (R.transpose() * xy.homogeneous()).normalized()};
  };
  TriangulationResult result = TriangulateMidpoint(ray(view_a, xy_a), ray(view_b, xy_b));
  if (result.parallel || std::abs(X.w()) < 1e-300) {
    result.parallel = true;
    return result;
  }
  result.point = X.head<3>() / X.w();
  return result;
}

}  // namespace saccade::geometry
