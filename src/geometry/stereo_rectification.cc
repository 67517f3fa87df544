#include "saccade/geometry/stereo_rectification.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "saccade/core/error.h"

namespace saccade::geometry {

StereoRectification RectifyStereo(const Eigen::Matrix3d& R, const Eigen::Vector3d& T) {
  constexpr double kRotationTolerance = 1e-5;  // as the calibration readers accept
  if (!R.allFinite() ||
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
          kRotationTolerance ||
      R.determinant() <= 0.0) {
    throw InvalidArgument("RectifyStereo: R is not a rotation matrix (R^T R = I, det R = 1)");
  }
  if (!T.allFinite() || T.norm() == 0.0) {
    throw InvalidArgument("RectifyStereo: T must be a finite, non-zero translation");
  }
  // cv::stereoRectify (calib3d/src/calibration.cpp): r_r turns each camera by half the rotation
  // between them, in opposite senses (its Rodrigues vector -om / 2).
  const Eigen::AngleAxisd om(R);
  const Eigen::Matrix3d r_r = Eigen::AngleAxisd(-0.5 * om.angle(), om.axis()).toRotationMatrix();
  const Eigen::Vector3d t = r_r * T;
  // Then both turn by wR, which brings t onto the x axis (y for a vertical pair).
  StereoRectification out;
  out.vertical = !(std::abs(t.x()) > std::abs(t.y()));
  const int idx = out.vertical ? 1 : 0;
  Eigen::Vector3d uu = Eigen::Vector3d::Zero();
  uu[idx] = t[idx] > 0 ? 1.0 : -1.0;
  Eigen::Vector3d ww = t.cross(uu);
  const double nw = ww.norm();
  Eigen::Matrix3d wR = Eigen::Matrix3d::Identity();
  if (nw > 0.0) {
    const double angle = std::acos(std::abs(t[idx]) / t.norm());
    wR = Eigen::AngleAxisd(angle, ww / nw).toRotationMatrix();
  }
  out.R1 = wR * r_r.transpose();
  out.R2 = wR * r_r;
  out.T_rect = out.R2 * T;
  return out;
}

}  // namespace saccade::geometry
