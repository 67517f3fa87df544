#include "saccade/vision/undistorter.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "internal_cv.h"
#include "saccade/core/error.h"
#include "saccade/geometry/distortion.h"
#include "saccade/geometry/image_camera.h"

namespace saccade::vision {

bool Undistorter::Options::IsValid(std::string* error) const {
  if (!kBorderValues.Contains(border_value)) {
    if (error)
      *error = "Undistorter::Options: " + kBorderValues.Refusal("border_value", border_value);
    return false;
  }
  return true;
}

Undistorter::Undistorter(const geometry::CameraModel& camera) : Undistorter(camera, Options()) {}

Undistorter::Undistorter(const geometry::CameraModel& camera, const Options& options)
    : camera_(camera),
      pinhole_(std::make_shared<const geometry::CameraModel>(camera.intrinsics())),
      options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
  const auto& in = camera.intrinsics();
  cv::Matx33d K(in.fx(), in.skew(), in.cx(), 0.0, in.fy(), in.cy(), 0.0, 0.0, 1.0);
  const cv::Size size(in.width(), in.height());
  const std::vector<double>& c = camera.distortion().coefficients();
  switch (camera.distortion().model()) {
    case geometry::DistortionModel::kFisheye:
      cv::fisheye::initUndistortRectifyMap(K, c, cv::Matx33d::eye(), K, size, CV_32FC1, map_x_,
                                           map_y_);
      break;
    case geometry::DistortionModel::kRadialTangential:
      cv::initUndistortRectifyMap(K, c, cv::Matx33d::eye(), K, size, CV_32FC1, map_x_, map_y_);
      break;
    case geometry::DistortionModel::kNone:
      cv::initUndistortRectifyMap(K, cv::noArray(), cv::Matx33d::eye(), K, size, CV_32FC1, map_x_,
                                  map_y_);
      break;
  }
}

Image Undistorter::Apply(const Image& image) const {
  const cv::Mat src = internal::WrapMat(image, "Undistorter::Apply");
  const auto& in = camera_.intrinsics();
  if (image.width() != in.width() || image.height() != in.height()) {
    throw InvalidArgument("Undistorter::Apply: image of " + std::to_string(image.width()) + " x " +
                          std::to_string(image.height()) + ", expected the camera's " +
                          std::to_string(in.width()) + " x " + std::to_string(in.height()));
  }
  Image out(image.width(), image.height(), image.format());
  cv::Mat dst(out.height(), out.width(), src.type(), out.data(), out.stride());
  cv::remap(src, dst, map_x_, map_y_, options_.bilinear ? cv::INTER_LINEAR : cv::INTER_NEAREST,
            cv::BORDER_CONSTANT, cv::Scalar::all(options_.border_value));
  out.metadata() = image.metadata();
  geometry::SetCameraModel(out.metadata(), pinhole_);
  return out;
}

cv::Point2f Undistorter::SourceOf(int u, int v) const {
  return {map_x_.at<float>(v, u), map_y_.at<float>(v, u)};
}

}  // namespace saccade::vision
