#include "saccade/geometry/camera_model.h"

namespace saccade::geometry {

std::optional<Eigen::Vector2d> CameraModel::Project(const Eigen::Vector3d& p_C) const {
  Eigen::Vector2d xd;
  if (!distortion_.DistortRay(p_C, &xd)) return std::nullopt;
  const Eigen::Vector2d uv = intrinsics_.NormalizedToPixel(xd);
  if (!uv.allFinite()) return std::nullopt;
  return uv;
}

std::optional<Eigen::Vector3d> CameraModel::Unproject(const Eigen::Vector2d& uv) const {
  Eigen::Vector3d ray_C;
  if (!distortion_.UndistortToRay(intrinsics_.PixelToNormalized(uv), &ray_C)) {
    return std::nullopt;
  }
  return ray_C;
}

Eigen::Vector2d CameraModel::DistortPixel(const Eigen::Vector2d& uv_undistorted) const {
  return intrinsics_.NormalizedToPixel(
      distortion_.Distort(intrinsics_.PixelToNormalized(uv_undistorted)));
}

UndistortResult CameraModel::UndistortPixel(const Eigen::Vector2d& uv_distorted) const {
  UndistortResult result = distortion_.Undistort(intrinsics_.PixelToNormalized(uv_distorted));
  // The point goes back to pixels; the residual stays in normalized units (UndistortResult).
  result.point = intrinsics_.NormalizedToPixel(result.point);
  return result;
}

bool CameraModel::Contains(const Eigen::Vector2d& uv) const {
  return uv.x() >= -0.5 && uv.x() < intrinsics_.width() - 0.5 && uv.y() >= -0.5 &&
         uv.y() < intrinsics_.height() - 0.5;
}

}  // namespace saccade::geometry
