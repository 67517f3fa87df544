#pragma once
// The camera a frame carries (core/image.h's typed values): its model, K and the lens
// distortion of the image as it is (a pinhole once undistorted), and its pose X_WC when the
// frame was taken; set by whoever makes the frame (the renderer, a camera source, the
// undistorter) and read by whoever measures in it.
#include <memory>

#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"

namespace saccade::geometry {

/// Sets the frame's camera model (shared: one per camera serves every frame).
inline void SetCameraModel(ImageMetadata& meta, std::shared_ptr<const CameraModel> model) {
  meta.typed.Set<CameraModel>(std::move(model));
}

/// nullptr when the frame carries none.
inline const CameraModel* FindCameraModel(const ImageMetadata& meta) {
  return meta.typed.Get<CameraModel>();
}

/// The camera's optical frame in the world (DESIGN.md's X_WC) at the frame's time.
struct CameraPose {
  Pose X_WC = Pose::Identity();
};

inline void SetCameraPose(ImageMetadata& meta, const Pose& X_WC) {
  meta.typed.Set<CameraPose>(std::make_shared<const CameraPose>(CameraPose{X_WC}));
}

/// nullptr when the frame carries none.
inline const Pose* FindCameraPose(const ImageMetadata& meta) {
  const CameraPose* pose = meta.typed.Get<CameraPose>();
  return pose ? &pose->X_WC : nullptr;
}

}  // namespace saccade::geometry
