#include "saccade/geometry/calibration_report.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "saccade/core/error.h"
#include "saccade/core/units.h"
#include "saccade/geometry/gl_projection.h"
#include "saccade/geometry/stereo_rectification.h"

namespace saccade::geometry {
namespace {

/// What both forms print of one camera, computed once.
struct Described {
  CameraCalibration calibration;
  Eigen::Matrix4d projection;
  double hfov_deg, vfov_deg;
};

Described Describe(const CameraCalibration& calibration, double near, double far) {
  Described d{calibration, {}, 0.0, 0.0};
  const Intrinsics& k = d.calibration.model.intrinsics();
  d.projection = GlProjectionFromIntrinsics(k, {near, far});
  d.hfov_deg = k.HorizontalFov() * kRadToDeg;
  d.vfov_deg = k.VerticalFov() * kRadToDeg;
  return d;
}

nlohmann::json Rows(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < m.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

// The camera's fields, without the file's.
nlohmann::json CameraJson(const Described& d, double near, double far) {
  const Intrinsics& k = d.calibration.model.intrinsics();
  const Distortion& distortion = d.calibration.model.distortion();
  nlohmann::json matrix = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    matrix.push_back(
        {d.projection(r, 0), d.projection(r, 1), d.projection(r, 2), d.projection(r, 3)});
  }
  return {{"name", d.calibration.name},
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

// The camera's lines, each indented by `indent`.
std::string CameraText(const Described& d, double near, double far, const std::string& indent) {
  const Intrinsics& k = d.calibration.model.intrinsics();
  const Distortion& distortion = d.calibration.model.distortion();
  std::string out = fmt::format("{}image      {} x {} px\n", indent, k.width(), k.height());
  out += fmt::format(
      "{0}fx fy      {1:.6f} {2:.6f} px\n{0}cx cy      {3:.6f} {4:.6f} px\n"
      "{0}skew       {5:.6f}\n",
      indent, k.fx(), k.fy(), k.cx(), k.cy(), k.skew());
  out += fmt::format("{}distortion {}", indent, ToString(distortion.model()));
  for (double c : distortion.coefficients()) out += fmt::format(" {:.9g}", c);
  out += fmt::format("\n{}field of view (pinhole) {:.3f} x {:.3f} deg\n", indent, d.hfov_deg,
                     d.vfov_deg);
  out += fmt::format("{}OpenGL projection (near {} m, far {} m), acting on eye coordinates:\n",
                     indent, near, far);
  for (int r = 0; r < 4; ++r) {
    out += fmt::format("{}  [{:+.9f} {:+.9f} {:+.9f} {:+.9f}]\n", indent, d.projection(r, 0),
                       d.projection(r, 1), d.projection(r, 2), d.projection(r, 3));
  }
  return out;
}

/// A stereo pair as read: both cameras, and R, T when the files give them.
struct Stereo {
  std::string source;  ///< what was read, for the first line
  CalibrationFormat format;
  Described left, right;
  std::optional<Eigen::Matrix3d> R;
  std::optional<Eigen::Vector3d> T;
};

bool IsStereo(const CalibrationReportInput& in) {
  return in.right.has_value() || IsStereoCalibrationFile(in.path);
}

Stereo ReadStereo(const CalibrationReportInput& in) {
  const CalibrationFormat format = DetectCalibrationFormat(in.path);
  if (in.right) {
    if (in.extrinsics) {
      throw InvalidArgument(
          "camera report: --extrinsics is for an OpenCV stereo file; a ROS pair's left and right "
          "camera_info files hold their pose themselves");
    }
    const StereoCalibration s = ReadRosStereoPair(in.path, *in.right, in.size);
    Stereo out{in.path.string() + " + " + in.right->string(),
               format,
               Describe({s.left, "left"}, in.near, in.far),
               Describe({s.right, "right"}, in.near, in.far),
               s.R,
               s.T};
    out.left.calibration.name = ReadCameraCalibration(in.path, in.size).name;
    out.right.calibration.name = ReadCameraCalibration(*in.right, in.size).name;
    return out;
  }
  const bool posed = in.extrinsics ? true : HasStereoExtrinsics(in.path);
  if (posed) {
    const StereoCalibration s = ReadStereoCalibration(in.path, in.extrinsics, in.size);
    return {in.path.string() + (in.extrinsics ? " + " + in.extrinsics->string() : ""),
            format,
            Describe({s.left, ""}, in.near, in.far),
            Describe({s.right, ""}, in.near, in.far),
            s.R,
            s.T};
  }
  return {in.path.string(),
          format,
          Describe(ReadStereoCameraCalibration(in.path, 1, in.size), in.near, in.far),
          Describe(ReadStereoCameraCalibration(in.path, 2, in.size), in.near, in.far),
          std::nullopt,
          std::nullopt};
}

// The angle between the two optical axes, in degrees: that of the left camera's z and the
// right camera's z seen from the left (R^T e_z).
double AxesAngleDeg(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d z2 = R.transpose() * Eigen::Vector3d::UnitZ();
  return std::acos(std::clamp(z2.z(), -1.0, 1.0)) * kRadToDeg;
}

void CheckOptions(const CalibrationReportInput& in) {
  if (in.extrinsics && !in.right && !IsStereoCalibrationFile(in.path)) {
    throw InvalidArgument("camera report: --extrinsics " + in.extrinsics->string() +
                          " is for a stereo file (M1 D1 M2 D2); " + in.path.string() +
                          " holds one camera");
  }
  if (in.right && DetectCalibrationFormat(in.path) != CalibrationFormat::kRosYaml) {
    throw InvalidArgument("camera report: --right is for a ROS pair; " + in.path.string() +
                          " is not a ROS camera_info file (an OpenCV stereo file holds both "
                          "cameras: give it alone)");
  }
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

nlohmann::json CalibrationReportJson(const CalibrationReportInput& in) {
  using nlohmann::json;
  CheckOptions(in);
  if (!IsStereo(in)) {
    json out = {{"file", in.path.string()}, {"format", ToString(DetectCalibrationFormat(in.path))}};
    out.update(CameraJson(Describe(ReadCameraCalibration(in.path, in.size), in.near, in.far),
                          in.near, in.far));
    return out;
  }
  const Stereo s = ReadStereo(in);
  json out = {{"file", in.path.string()},
              {"format", ToString(s.format)},
              {"stereo", true},
              {"left", CameraJson(s.left, in.near, in.far)},
              {"right", CameraJson(s.right, in.near, in.far)}};
  if (in.right) out["right_file"] = in.right->string();
  if (in.extrinsics) out["extrinsics_file"] = in.extrinsics->string();
  if (s.R && s.T) {
    const Eigen::AngleAxisd aa(*s.R);
    const StereoRectification rect = RectifyStereo(*s.R, *s.T);
    out["R"] = Rows(*s.R);
    out["T"] = {s.T->x(), s.T->y(), s.T->z()};
    out["baseline"] = s.T->norm();
    out["rotation_deg"] = aa.angle() * kRadToDeg;
    out["rotation_axis"] = {aa.axis().x(), aa.axis().y(), aa.axis().z()};
    out["optical_axes_angle_deg"] = AxesAngleDeg(*s.R);
    out["rectification"] = {{"R1", Rows(rect.R1)},
                            {"R2", Rows(rect.R2)},
                            {"T_rect", {rect.T_rect.x(), rect.T_rect.y(), rect.T_rect.z()}},
                            {"left_turn_deg", Eigen::AngleAxisd(rect.R1).angle() * kRadToDeg},
                            {"right_turn_deg", Eigen::AngleAxisd(rect.R2).angle() * kRadToDeg},
                            {"vertical", rect.vertical}};
  }
  return out;
}

std::string CalibrationReportText(const CalibrationReportInput& in) {
  CheckOptions(in);
  if (!IsStereo(in)) {
    const Described d = Describe(ReadCameraCalibration(in.path, in.size), in.near, in.far);
    std::string out =
        fmt::format("{} ({}{})\n", in.path.string(), ToString(DetectCalibrationFormat(in.path)),
                    d.calibration.name.empty() ? "" : ", camera " + d.calibration.name);
    return out + CameraText(d, in.near, in.far, "  ");
  }
  const Stereo s = ReadStereo(in);
  std::string out = fmt::format("{} ({}, a stereo pair)\n", s.source, ToString(s.format));
  const auto camera = [&](const char* label, const Described& d) {
    out += fmt::format("  {} camera{}{}\n", label, d.calibration.name.empty() ? "" : " ",
                       d.calibration.name);
    out += CameraText(d, in.near, in.far, "    ");
  };
  camera("left (1: M1 D1)", s.left);
  camera("right (2: M2 D2)", s.right);
  if (!s.R || !s.T) {
    out +=
        "  no R and T: the file holds the two cameras' intrinsics only; give the pose with "
        "--extrinsics FILE (R, T: OpenCV's stereo_calib writes extrinsics.yml)\n";
    return out;
  }
  const Eigen::Matrix3d& R = *s.R;
  const Eigen::Vector3d& T = *s.T;
  const Eigen::AngleAxisd aa(R);
  out += "  right camera in the left (p_right = R p_left + T, cv::stereoCalibrate):\n";
  for (int r = 0; r < 3; ++r) {
    out += fmt::format(
        "    R [{:+.9f} {:+.9f} {:+.9f}]{}\n", R(r, 0), R(r, 1), R(r, 2),
        r == 1 ? fmt::format("   T [{:+.9g} {:+.9g} {:+.9g}]", T.x(), T.y(), T.z()) : "");
  }
  out += fmt::format(
      "    baseline |T| {:.9g} (the calibration's unit: the pattern's, metres if its squares "
      "were given in metres)\n",
      T.norm());
  out += fmt::format(
      "    rotation {:.6f} deg about [{:+.6f} {:+.6f} {:+.6f}]; optical axes {:.6f} deg apart\n",
      aa.angle() * kRadToDeg, aa.axis().x(), aa.axis().y(), aa.axis().z(), AxesAngleDeg(R));
  const StereoRectification rect = RectifyStereo(R, T);
  out += fmt::format(
      "  rectification (Bouguet, as cv::stereoRectify): the left camera turns {:.6f} deg, the "
      "right {:.6f} deg; then {} are epipolar lines\n",
      Eigen::AngleAxisd(rect.R1).angle() * kRadToDeg,
      Eigen::AngleAxisd(rect.R2).angle() * kRadToDeg, rect.vertical ? "columns" : "rows");
  for (int r = 0; r < 3; ++r) {
    out += fmt::format("    R1 [{:+.9f} {:+.9f} {:+.9f}]   R2 [{:+.9f} {:+.9f} {:+.9f}]\n",
                       rect.R1(r, 0), rect.R1(r, 1), rect.R1(r, 2), rect.R2(r, 0), rect.R2(r, 1),
                       rect.R2(r, 2));
  }
  out += fmt::format("    T_rect [{:+.9g} {:+.9g} {:+.9g}] (P2 = K' [I | T_rect])\n",
                     rect.T_rect.x(), rect.T_rect.y(), rect.T_rect.z());
  return out;
}

nlohmann::json CalibrationReportJson(const std::filesystem::path& path, double near, double far) {
  return CalibrationReportJson(CalibrationReportInput{path, {}, {}, {}, near, far});
}

std::string CalibrationReportText(const std::filesystem::path& path, double near, double far) {
  return CalibrationReportText(CalibrationReportInput{path, {}, {}, {}, near, far});
}

}  // namespace saccade::geometry
