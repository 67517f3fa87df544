#pragma once
// Rigid transforms. A pose X_AB is frame B expressed in frame A: p_A = X_AB * p_B (metres).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace saccade::geometry {

using Pose = Eigen::Isometry3d;

/// Rotation from roll, pitch, yaw (radians) about fixed x, y, z axes: R = Rz(yaw) Ry(pitch)
/// Rx(roll) (REP 103).
Eigen::Matrix3d RotationFromRpy(double roll, double pitch, double yaw);
/// Roll, pitch, yaw of a rotation (inverse of RotationFromRpy; pitch in [-pi/2, pi/2]).
Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& R);
/// A pose from a rotation and a translation.
Pose MakePose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

}  // namespace saccade::geometry
