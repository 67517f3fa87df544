#pragma once
// The camera of an image, read back from the metadata every frame carries (core/image.h):
// its model (K and distortion, at the image's size) and its pose X_WC.
#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"

namespace saccade::vision {

/// The camera model `image` carries (geometry/image_camera.h). Throws InvalidArgument naming
/// the camera when it carries none or one of another image size.
geometry::CameraModel CameraModelOf(const Image& image);

/// X_WC of `image`'s optical frame (metres), from its metadata; InvalidArgument when the
/// image carries none.
geometry::Pose CameraPoseOf(const Image& image);

}  // namespace saccade::vision
