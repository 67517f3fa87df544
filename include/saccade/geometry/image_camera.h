#pragma once
// The camera model a frame carries (core/image.h's typed values): K and the lens distortion
// of the image as it is (a pinhole once undistorted), set by whoever makes the frame (the
// renderer, a camera source, the undistorter) and read by whoever measures in it.
#include <memory>

#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"

namespace saccade::geometry {

/// Sets the frame's camera model (shared: one per camera serves every frame).
inline void SetCameraModel(ImageMetadata& meta, std::shared_ptr<const CameraModel> model) {
  meta.typed.Set<CameraModel>(std::move(model));
}

/// nullptr when the frame carries none.
inline const CameraModel* FindCameraModel(const ImageMetadata& meta) {
  return meta.typed.Get<CameraModel>();
}

}  // namespace saccade::geometry
