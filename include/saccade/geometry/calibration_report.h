#pragma once
// What `saccade camera` prints about a calibration, as JSON (docs/cli.md) and as text: for
// one camera its intrinsics, distortion, field of view and the OpenGL projection for
// [near, far]; for a stereo pair (OpenCV's M1 D1 M2 D2 [R T], or a ROS left/right pair) both
// cameras, then R and T, the baseline, the angle between the optical axes and the
// rectification (stereo_rectification.h).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "saccade/geometry/calibration_io.h"

namespace saccade::geometry {

/// "opencv-yaml", "opencv-xml" or "ros-yaml".
const char* ToString(CalibrationFormat format);

/// What to describe.
struct CalibrationReportInput {
  /// One camera (OpenCV or ROS), a stereo file (M1 D1 M2 D2, with R T or not), or the left
  /// camera_info of a ROS pair (with `right`).
  std::filesystem::path path;
  /// The right camera_info of a ROS stereo pair.
  std::optional<std::filesystem::path> right;
  /// R and T of a stereo file that stores none (OpenCV's stereo_calib writes extrinsics.yml).
  std::optional<std::filesystem::path> extrinsics;
  /// The image size, for files that store none (stereo_calib's intrinsics.yml).
  std::optional<ImageSize> size;
  double near = 0.01;  ///< clip planes of the OpenGL projection, metres
  double far = 100.0;
};

/// Reads the calibration and describes it. Throws FileError (file, line, key) as the readers;
/// InvalidArgument for options that do not fit the file (`right` with an OpenCV file,
/// `extrinsics` without a stereo file).
nlohmann::json CalibrationReportJson(const CalibrationReportInput& input);
std::string CalibrationReportText(const CalibrationReportInput& input);

/// One camera file: CalibrationReportJson({path, ..., near, far}).
nlohmann::json CalibrationReportJson(const std::filesystem::path& path, double near, double far);
std::string CalibrationReportText(const std::filesystem::path& path, double near, double far);

}  // namespace saccade::geometry
