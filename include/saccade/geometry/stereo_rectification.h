#pragma once
// The rectification of a calibrated stereo pair: the rotations that turn both cameras into a
// common orientation in which corresponding points lie on the same image row (or column, for a
// pair one above the other). Bouguet's method, as cv::stereoRectify computes R1 and R2: each
// camera turns by half the rotation between them, then both turn together so that the
// baseline lies along the rectified x axis (y for a vertical pair). On a vergence head the
// angles grow with the vergence: the eyes converge, the rectified views do not.

#include <Eigen/Core>

namespace saccade::geometry {

/// Rotations into the rectified frame and the pair's offsets there.
struct StereoRectification {
  /// p_rect = R1 p1: camera 1's (left's) optical frame into the rectified frame.
  Eigen::Matrix3d R1 = Eigen::Matrix3d::Identity();
  /// p_rect2 = R2 p2: camera 2's (right's) optical frame into its rectified frame.
  Eigen::Matrix3d R2 = Eigen::Matrix3d::Identity();
  /// R2 T: camera 1's centre seen from camera 2 in the rectified frame; only its x (y for a
  /// vertical pair) is non-zero. cv::stereoRectify's P2 is K' [I | T_rect].
  Eigen::Vector3d T_rect = Eigen::Vector3d::Zero();
  bool vertical = false;  ///< the baseline lies mostly along y: rows become columns
};

/// The rectification of cameras whose relative pose is R, T (cv::stereoCalibrate's
/// convention: p2 = R p1 + T). R must be a rotation and T non-zero; throws InvalidArgument
/// otherwise. Agrees with cv::stereoRectify's R1 and R2 to rounding (geometry tests).
StereoRectification RectifyStereo(const Eigen::Matrix3d& R, const Eigen::Vector3d& T);

}  // namespace saccade::geometry
