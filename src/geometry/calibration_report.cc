#include "saccade/geometry/calibration_report.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>

#include "saccade/geometry/gl_projection.h"

namespace saccade::geometry {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

/// Everything both forms print, read once.
struct Described {
  CalibrationFormat format;
  CameraCalibration calibration;
  Eigen::Matrix4d projection;
  double hfov_deg, vfov_deg;
};

Described Describe(const std::filesystem::path& path, double near, double far) {
  Described d{DetectCalibrationFormat(path), ReadCameraCalibration(path), {}, 0.0, 0.0};
  const Intrinsics& k = d.calibration.model.intrinsics();
  d.projection = GlProjectionFromIntrinsics(k, {near, far});
  d.hfov_deg = k.HorizontalFov() * kRadToDeg;
  d.vfov_deg = k.VerticalFov() * kRadToDeg;
  return d;
}

}  // namespace

const char* ToString(CalibrationFormat format) {
  switch (format) {
    case CalibrationFormat::kOpenCvYaml:
      return "opencv-yaml";
    case CalibrationFormat::kOpenCvXml:
      return "opencv-xml";
    case CalibrationFormat::kRosYaml:
      return "ros-yaml";
  }
  return "unknown";
}

nlohmann::json CalibrationReportJson(const std::filesystem::path& path, double near, double far) {
  using nlohmann::json;
  const Described d = Describe(path, near, far);
  const Intrinsics& k = d.calibration.model.intrinsics();
  const Distortion& distortion = d.calibration.model.distortion();
  json matrix = json::array();
  for (int r = 0; r < 4; ++r) {
    matrix.push_back(
        {d.projection(r, 0), d.projection(r, 1), d.projection(r, 2), d.projection(r, 3)});
  }
  return {{"file", path.string()},
          {"format", ToString(d.format)},
          {"name", d.calibration.name},
          {"width", k.width()},
          {"height", k.height()},
          {"fx", k.fx()},
          {"fy", k.fy()},
          {"cx", k.cx()},
          {"cy", k.cy()},
          {"skew", k.skew()},
          {"distortion",
           {{"model", ToString(distortion.model())}, {"coefficients", distortion.coefficients()}}},
          {"fov_deg", {{"horizontal", d.hfov_deg}, {"vertical", d.vfov_deg}}},
          {"near", near},
          {"far", far},
          {"gl_projection", matrix}};
}

std::string CalibrationReportText(const std::filesystem::path& path, double near, double far) {
  const Described d = Describe(path, near, far);
  const Intrinsics& k = d.calibration.model.intrinsics();
  const Distortion& distortion = d.calibration.model.distortion();
  std::string out = fmt::format("{} ({}{})\n", path.string(), ToString(d.format),
                                d.calibration.name.empty() ? "" : ", camera " + d.calibration.name);
  out += fmt::format("  image      {} x {} px\n", k.width(), k.height());
  out += fmt::format(
      "  fx fy      {:.6f} {:.6f} px\n  cx cy      {:.6f} {:.6f} px\n  skew       {:.6f}\n", k.fx(),
      k.fy(), k.cx(), k.cy(), k.skew());
  out += fmt::format("  distortion {}", ToString(distortion.model()));
  for (double c : distortion.coefficients()) out += fmt::format(" {:.9g}", c);
  out += fmt::format("\n  field of view (pinhole) {:.3f} x {:.3f} deg\n", d.hfov_deg, d.vfov_deg);
  out += fmt::format("  OpenGL projection (near {} m, far {} m), acting on eye coordinates:\n",
                     near, far);
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("    [{:+.9f} {:+.9f} {:+.9f} {:+.9f}]\n", d.projection(r, 0),
                       d.projection(r, 1), d.projection(r, 2), d.projection(r, 3));
  }
  return out;
}

}  // namespace saccade::geometry
