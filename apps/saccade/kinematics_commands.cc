// fk, ik, camera: the kinematics and camera-model subcommands.

#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/geometry/gl_projection.h"
#include "saccade/head/head_description.h"
#include "saccade/head/kinematics.h"

namespace saccade::app {
namespace {

using nlohmann::json;
using saccade::geometry::Pose;
using saccade::head::HeadDescription;
using saccade::head::JointState;

json JointsDegJson(const JointState& q) {
  return ToJson(
      JointState{q.pan * kRadToDeg, q.tilt * kRadToDeg, q.left * kRadToDeg, q.right * kRadToDeg});
}

std::string FormatVector(const Eigen::Vector3d& v) {
  return fmt::format("[{:+.6f}, {:+.6f}, {:+.6f}]", v.x(), v.y(), v.z());
}

std::string FormatJointsDeg(const JointState& q) {
  return fmt::format("pan {:+.4f}  tilt {:+.4f}  left {:+.4f}  right {:+.4f}  (deg)",
                     q.pan * kRadToDeg, q.tilt * kRadToDeg, q.left * kRadToDeg,
                     q.right * kRadToDeg);
}

void PrintPose(const char* name, const Pose& X) {
  const Eigen::Vector3d z = X.linear().col(2);
  fmt::print("  {:<14} position {} m   optical axis {}\n", name, FormatVector(X.translation()),
             FormatVector(z));
}

void PrintFrames(const saccade::head::HeadFrames& frames) {
  PrintPose("left camera", frames.X_WCamLeft);
  PrintPose("right camera", frames.X_WCamRight);
  if (frames.p_WFixation) {
    fmt::print("  fixation       {} m\n", FormatVector(*frames.p_WFixation));
  } else {
    fmt::print("  fixation       none (optical axes parallel or diverging)\n");
  }
}

int RunFk(const std::string& head_path, const std::vector<double>& joint_values, bool degrees,
          bool as_json) {
  const HeadDescription head = HeadDescription::FromYamlFile(head_path);
  const JointState q = JointsFromArgs(joint_values, degrees);
  const auto frames = saccade::head::ForwardKinematics(head, q);
  const bool within = head.WithinLimits(q);
  if (as_json) {
    json out = {{"head", head.name()},
                {"joints", ToJson(q)},
                {"within_limits", within},
                {"cameras",
                 {{"left", PoseJson(frames.X_WCamLeft)}, {"right", PoseJson(frames.X_WCamRight)}}},
                {"fixation", frames.p_WFixation ? ToJson<Eigen::Vector3d>(*frames.p_WFixation)
                                                : json(nullptr)}};
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  fmt::print("joints: {}\n", FormatJointsDeg(q));
  if (!within) {
    try {
      head.CheckLimits(q);
    } catch (const saccade::Error& e) {
      fmt::print("warning: {}\n", e.what());
    }
  }
  PrintFrames(frames);
  return 0;
}

int RunIk(const std::string& head_path, const std::vector<double>& target, const std::string& mode,
          bool as_json) {
  const HeadDescription head = HeadDescription::FromYamlFile(head_path);
  const Eigen::Vector3d p_W(target[0], target[1], target[2]);
  saccade::head::IkOptions options;
  options.mode = mode == "independent" ? saccade::head::VergenceMode::kIndependent
                                       : saccade::head::VergenceMode::kSymmetric;
  const auto result = saccade::head::SolveFixation(head, p_W, options);
  if (as_json) {
    json out = {{"head", head.name()},
                {"target", ToJson<Eigen::Vector3d>(p_W)},
                {"mode", mode},
                {"reachable", result.reachable()},
                {"reachability", saccade::head::ToString(result.reachability)},
                {"message", result.message},
                {"joints", ToJson(result.joints)},
                {"joints_deg", JointsDegJson(result.joints)},
                {"axis_error_rad", result.axis_error},
                {"iterations", result.iterations}};
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  fmt::print("target {} m in the world\n", FormatVector(p_W));
  fmt::print("joints: {}\n", FormatJointsDeg(result.joints));
  if (result.reachable()) {
    fmt::print(
        "reachable: both optical axes pass through the target (axis error {:.2e} rad, "
        "{} iterations)\n",
        result.axis_error, result.iterations);
  } else {
    fmt::print(
        "NOT reachable ({}): {}\n  the joints above are the nearest reachable "
        "(axis error {:.4f} deg)\n",
        saccade::head::ToString(result.reachability), result.message,
        result.axis_error * kRadToDeg);
  }
  return 0;
}

const char* FormatName(saccade::geometry::CalibrationFormat format) {
  switch (format) {
    case saccade::geometry::CalibrationFormat::kOpenCvYaml:
      return "opencv-yaml";
    case saccade::geometry::CalibrationFormat::kOpenCvXml:
      return "opencv-xml";
    case saccade::geometry::CalibrationFormat::kRosYaml:
      return "ros-yaml";
  }
  return "unknown";
}

int RunCamera(const std::string& path, double near, double far, bool as_json) {
  namespace g = saccade::geometry;
  const auto format = g::DetectCalibrationFormat(path);
  const g::CameraCalibration calibration = g::ReadCameraCalibration(path);
  const g::Intrinsics& k = calibration.model.intrinsics();
  const g::Distortion& d = calibration.model.distortion();
  const Eigen::Matrix4d P = g::GlProjectionFromIntrinsics(k, {near, far});
  const double hfov = k.HorizontalFov() * kRadToDeg, vfov = k.VerticalFov() * kRadToDeg;
  if (as_json) {
    json matrix = json::array();
    for (int r = 0; r < 4; ++r) matrix.push_back({P(r, 0), P(r, 1), P(r, 2), P(r, 3)});
    json out = {
        {"file", path},
        {"format", FormatName(format)},
        {"name", calibration.name},
        {"width", k.width()},
        {"height", k.height()},
        {"fx", k.fx()},
        {"fy", k.fy()},
        {"cx", k.cx()},
        {"cy", k.cy()},
        {"skew", k.skew()},
        {"distortion", {{"model", g::ToString(d.model())}, {"coefficients", d.coefficients()}}},
        {"fov_deg", {{"horizontal", hfov}, {"vertical", vfov}}},
        {"near", near},
        {"far", far},
        {"gl_projection", matrix}};
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  fmt::print("{} ({}{})\n", path, FormatName(format),
             calibration.name.empty() ? "" : ", camera " + calibration.name);
  fmt::print("  image      {} x {} px\n", k.width(), k.height());
  fmt::print("  fx fy      {:.6f} {:.6f} px\n  cx cy      {:.6f} {:.6f} px\n  skew       {:.6f}\n",
             k.fx(), k.fy(), k.cx(), k.cy(), k.skew());
  fmt::print("  distortion {}", g::ToString(d.model()));
  for (double c : d.coefficients()) fmt::print(" {:.9g}", c);
  fmt::print("\n  field of view (pinhole) {:.3f} x {:.3f} deg\n", hfov, vfov);
  fmt::print("  OpenGL projection (near {} m, far {} m), acting on eye coordinates:\n", near, far);
  for (int r = 0; r < 4; ++r) {
    fmt::print("    [{:+.9f} {:+.9f} {:+.9f} {:+.9f}]\n", P(r, 0), P(r, 1), P(r, 2), P(r, 3));
  }
  return 0;
}

}  // namespace

Runner AddFkCommand(CLI::App& app) {
  struct Options {
    std::string head = ShippedFile("robots/popeye.yaml");
    std::vector<double> joints;
    bool degrees = false, json = false;
  };
  auto o = std::make_shared<Options>();
  auto* fk = app.add_subcommand("fk",
                                "Forward kinematics: camera poses and fixation point for "
                                "joint angles (seed appendix A, eqs. 4-9).");
  fk->add_option("--head", o->head, "Head description YAML")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  fk->add_option("--joints", o->joints, "PAN TILT LEFT RIGHT (radians, or degrees with --deg)")
      ->expected(4)
      ->required();
  fk->add_flag("--deg", o->degrees, "Joint angles are in degrees");
  fk->add_flag("--json", o->json, "Print JSON (stable interface, docs/cli.md)");
  return [o] { return RunFk(o->head, o->joints, o->degrees, o->json); };
}

Runner AddIkCommand(CLI::App& app) {
  struct Options {
    std::string head = ShippedFile("robots/popeye.yaml");
    std::vector<double> target;
    std::string mode = "symmetric";
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* ik = app.add_subcommand("ik",
                                "Inverse kinematics: joint angles that fixate a 3D point "
                                "with both optical axes (eqs. 10-13, general solver).");
  ik->add_option("--head", o->head, "Head description YAML")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  ik->add_option("--target", o->target, "X Y Z of the point to fixate, in metres, world frame")
      ->expected(3)
      ->required();
  ik->add_option("--mode", o->mode, "symmetric (left = -right) or independent (pan held at 0)")
      ->check(CLI::IsMember({"symmetric", "independent"}))
      ->capture_default_str();
  ik->add_flag("--json", o->json, "Print JSON (stable interface, docs/cli.md)");
  return [o] { return RunIk(o->head, o->target, o->mode, o->json); };
}

Runner AddCameraCommand(CLI::App& app) {
  struct Options {
    std::string calibration;
    double near = 0.01, far = 100.0;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* camera = app.add_subcommand("camera",
                                    "Describe a calibration file: intrinsics, "
                                    "distortion, field of view, OpenGL projection.");
  camera
      ->add_option("--calibration", o->calibration,
                   "OpenCV YAML/XML or ROS camera_info YAML calibration file")
      ->check(CLI::ExistingFile)
      ->required();
  camera->add_option("--near", o->near, "Near clip plane of the OpenGL projection (m)")
      ->capture_default_str();
  camera->add_option("--far", o->far, "Far clip plane of the OpenGL projection (m)")
      ->capture_default_str();
  camera->add_flag("--json", o->json, "Print JSON (stable interface, docs/cli.md)");
  return [o] { return RunCamera(o->calibration, o->near, o->far, o->json); };
}

}  // namespace saccade::app
