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
  const Eigen::Matrix4d X =
      Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(image.metadata().X_WC.data());
  geometry::Pose pose = geometry::Pose::Identity();
  pose.linear() = X.topLeftCorner<3, 3>();
  pose.translation() = X.topRightCorner<3, 1>();
  return pose;
}

}  // namespace saccade::vision
