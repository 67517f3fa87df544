#pragma once
// Undistortion (seed Fig. 2, pre-processing): the image a pinhole camera with the same K
// would have taken. The remap tables are computed once per camera (cv::initUndistortRectifyMap
// or cv::fisheye::initUndistortRectifyMap with K as the new camera matrix) and reused.
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"
#include "saccade/geometry/camera_model.h"

namespace saccade::vision {

/// Removes a camera's lens distortion. Thread-safe after construction (Apply is const).
class Undistorter {
 public:
  struct Options {
    /// Bilinear (true) or nearest-neighbour (false) sampling of the distorted image.
    bool bilinear = true;
    /// Value of output pixels whose ray falls outside the distorted image: kBorderValues.
    int border_value = 0;

    // The valid values, stated once: IsValid checks them, and vision.undistort declares its
    // parameter with them (runtime::ParamDecl::Range(const Interval&)).
    static constexpr Interval kBorderValues = Interval::Closed(0, 255);

    bool IsValid(std::string* error) const;
  };

  /// Precomputes the maps for `camera`. Throws InvalidArgument with IsValid's message.
  explicit Undistorter(const geometry::CameraModel& camera);  ///< default Options
  Undistorter(const geometry::CameraModel& camera, const Options& options);

  /// The undistorted image (same size, format and metadata, distortion "none" with no
  /// coefficients). `image` must be rgb8, rgba8 or gray8 of the camera's size; throws
  /// InvalidArgument otherwise (a wiring error, not a per-frame condition).
  Image Apply(const Image& image) const;

  /// Where the undistorted pixel (u, v) samples the distorted image (for tests and overlays).
  cv::Point2f SourceOf(int u, int v) const;

  const geometry::CameraModel& camera() const { return camera_; }

 private:
  geometry::CameraModel camera_;
  std::shared_ptr<const geometry::CameraModel> pinhole_;  // the output's: K, no distortion
  Options options_;
  cv::Mat map_x_;  // CV_32FC1
  cv::Mat map_y_;
};

}  // namespace saccade::vision
