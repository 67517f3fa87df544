#include "saccade/vision/image_camera.h"

#include <Eigen/Core>
#include <string>

#include "saccade/core/error.h"
#include "saccade/geometry/distortion.h"
#include "saccade/geometry/intrinsics.h"

namespace saccade::vision {

geometry::CameraModel CameraModelOf(const Image& image) {
  const ImageMetadata& m = image.metadata();
  const Eigen::Matrix3d K =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.K.data());
  const geometry::Intrinsics intrinsics =
      geometry::Intrinsics::FromMatrix(K, image.width(), image.height());
  const std::string& model = m.distortion_model;
  geometry::Distortion distortion;
  if (model == "radtan") {
    distortion = geometry::Distortion::RadialTangential(m.distortion);
  } else if (model == "fisheye") {
    distortion = geometry::Distortion::Fisheye(m.distortion);
  } else if (model == "none" || model.empty()) {
    distortion =
        geometry::Distortion::FromCoefficients(geometry::DistortionModel::kNone, m.distortion);
  } else {
    throw InvalidArgument("CameraModelOf: image of camera '" + m.camera + "': distortion model '" +
                          model + "', expected none, radtan or fisheye");
  }
  return geometry::CameraModel(intrinsics, distortion);
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
