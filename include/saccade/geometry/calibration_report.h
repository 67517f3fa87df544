#pragma once
// What `saccade camera` prints about a calibration file: intrinsics, distortion, field of
// view and the OpenGL projection for [near, far], as JSON (docs/cli.md) and as text.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "saccade/geometry/calibration_io.h"

namespace saccade::geometry {

/// "opencv-yaml", "opencv-xml" or "ros-yaml".
const char* ToString(CalibrationFormat format);

/// Reads `path` (any format ReadCameraCalibration reads) and describes it.
nlohmann::json CalibrationReportJson(const std::filesystem::path& path, double near, double far);
std::string CalibrationReportText(const std::filesystem::path& path, double near, double far);

}  // namespace saccade::geometry
