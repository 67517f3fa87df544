#include "saccade/geometry/pose.h"

#include <algorithm>
#include <cmath>

namespace saccade::geometry {

Eigen::Matrix3d RotationFromRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

Pose MakePose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Pose X = Pose::Identity();
  X.linear() = R;
  X.translation() = t;
  return X;
}

}  // namespace saccade::geometry
