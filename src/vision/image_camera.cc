#include "saccade/vision/image_camera.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <string>

#include "saccade/core/error.h"
#include "saccade/geometry/distortion.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/geometry/intrinsics.h"

namespace saccade::vision {

geometry::CameraModel CameraModelOf(const Image& image) {
  const ImageMetadata& m = image.metadata();
  const geometry::CameraModel* model = geometry::FindCameraModel(m);
  if (model == nullptr) {
    throw InvalidArgument("CameraModelOf: image of camera '" + m.camera +
                          "' carries no camera model");
  }
  const geometry::Intrinsics& k = model->intrinsics();
  if (k.width() != image.width() || k.height() != image.height()) {
    throw InvalidArgument(
        fmt::format("CameraModelOf: image of camera '{}' is {}x{}, its camera model {}x{}",
                    m.camera, image.width(), image.height(), k.width(), k.height()));
  }
  return *model;
}

geometry::Pose CameraPoseOf(const Image& image) {
  const geometry::Pose* X_WC = geometry::FindCameraPose(image.metadata());
  if (X_WC == nullptr) {
    throw InvalidArgument("CameraPoseOf: image of camera '" + image.metadata().camera +
                          "' carries no camera pose");
  }
  return *X_WC;
}

}  // namespace saccade::vision
