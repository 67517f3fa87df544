#pragma once
// The stereo head's description: geometry (seed appendix A), joint limits, cameras, pose.
// Immutable once loaded; joint angles live apart in PopeyeJoints (description vs state).
//
// Frames. W: world, z up. B: head base (REP 103: x forward, y left, z up), placed in W by
// X_WB. The paper's frames {b, n, c, l, r} use x left, y up, z forward; saccade keeps the
// paper's equations in those frames and maps them into B with a fixed rotation. The eye
// cameras' optical frames are OpenCV's (x right, y down, z forward): eqs. 7-8.
//
// Joints (radians, signs as the paper's and REP 103's):
//   pan   > 0 turns the head to the left (about up),
//   tilt  > 0 tilts it down (about left),
//   left, right > 0 turn that eye to the left (about up). Converging eyes: left < 0 < right;
//   symmetric vergence: left = -right (paper's assumption).

#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/joint_state.h"

namespace saccade::head {

enum class Joint { kPan = 0, kTilt = 1, kLeft = 2, kRight = 3 };
inline constexpr std::array<Joint, 4> kAllJoints = {Joint::kPan, Joint::kTilt, Joint::kLeft,
                                                    Joint::kRight};
/// "pan", "tilt", "left", "right".
const char* JointName(Joint joint);

/// Joint angles in radians.
struct PopeyeJoints {
  double pan = 0.0;
  double tilt = 0.0;
  double left = 0.0;
  double right = 0.0;
  double& operator[](Joint joint);
  double operator[](Joint joint) const;
  double& operator[](int joint) { return (*this)[static_cast<Joint>(joint)]; }
  double operator[](int joint) const { return (*this)[static_cast<Joint>(joint)]; }
  /// POPEYE's joints of a JointState, by name (throws InvalidArgument when one is missing).
  static PopeyeJoints From(const JointState& q) {
    return {q.at("pan"), q.at("tilt"), q.at("left"), q.at("right")};
  }
  /// As a JointState named pan, tilt, left, right (POPEYE's legacy code and tests).
  operator JointState() const { return JointState::Popeye(pan, tilt, left, right); }
  bool operator==(const PopeyeJoints&) const = default;
};

/// Range of one joint: position (rad), velocity (rad/s) and acceleration (rad/s^2) limits.
struct JointLimits {
  double min = 0.0;
  double max = 0.0;
  double max_velocity = 0.0;
  double max_acceleration = 0.0;
  bool Contains(double angle) const { return angle >= min && angle <= max; }
};

/// How a joint maps onto the servo that drives it (issue 7: a head built from bus servos,
/// e.g. Dynamixel). The servo's shaft angle, measured from the servo's own zero position, is
///   servo_angle = zero_offset + direction * gear_ratio * joint_angle      (rad)
/// so zero_offset is where the servo stands when the joint is at 0, direction (+1 or -1)
/// tells which way the servo turns when the joint angle grows, and gear_ratio is servo turns
/// per joint turn. The simulator ignores it; hw's servo drivers use it.
struct ServoMapping {
  int id = 1;                ///< servo id on its bus, 0..252
  double zero_offset = 0.0;  ///< rad, servo angle at joint angle 0
  int direction = 1;         ///< +1 or -1
  double gear_ratio = 1.0;   ///< > 0
  /// The servo's shaft angle (rad) for a joint angle (rad), and back; velocities scale by
  /// direction * gear_ratio.
  double ServoAngle(double joint_angle) const {
    return zero_offset + direction * gear_ratio * joint_angle;
  }
  double JointAngle(double servo_angle) const {
    return (servo_angle - zero_offset) / (direction * gear_ratio);
  }
};

/// Lengths of appendix A, in metres.
struct HeadGeometry {
  double B = 0.1;        ///< half baseline: each eye's rotation axis is B from the cyclopean point
  double D = 0.0;        ///< eq. 4: height of the cyclopean point above the pan/neck origin
  double H = 0.0;        ///< extension: the eye baseline sits H above the tilt axis and turns
                         ///< with it (0 in the paper, where the tilt axis passes through it)
  double delta_l = 0.0;  ///< eq. 7: left optical centre ahead of its eye's rotation axis
  double delta_r = 0.0;  ///< eq. 8: right optical centre ahead of its eye's rotation axis
};

/// A stereo head. Construct with FromYamlFile/FromYamlString or the validating constructor.
class HeadDescription {
 public:
  /// Throws InvalidArgument naming the field when B <= 0, a length is not finite, a limit range
  /// is empty or does not contain 0, a velocity/acceleration limit is not positive, or a servo
  /// mapping is invalid (id outside 0..252 or used twice, direction not +-1, gear ratio not
  /// positive, offset not finite).
  HeadDescription(std::string name, const HeadGeometry& geometry,
                  const std::array<JointLimits, 4>& limits, const geometry::Pose& X_WB,
                  const geometry::CameraModel& left_camera,
                  const geometry::CameraModel& right_camera,
                  const std::array<std::optional<ServoMapping>, 4>& servos = {});

  /// Loads a head description YAML (robots/popeye.yaml documents the format). Throws
  /// saccade::FileError with file, line and key on a missing, malformed or invalid entry,
  /// and on unknown keys.
  static HeadDescription FromYamlFile(const std::filesystem::path& path);
  /// Same from text; `source` names it in errors.
  static HeadDescription FromYamlString(const std::string& text, const std::string& source);

  const std::string& name() const { return name_; }
  const HeadGeometry& geometry() const { return geometry_; }
  const JointLimits& limits(Joint joint) const { return limits_[static_cast<int>(joint)]; }
  /// The head base in the world.
  const geometry::Pose& X_WB() const { return X_WB_; }
  const geometry::CameraModel& left_camera() const { return left_camera_; }
  const geometry::CameraModel& right_camera() const { return right_camera_; }

  /// The servo that drives the joint, when the description says (`servo:` in the YAML).
  const std::optional<ServoMapping>& servo(Joint joint) const {
    return servos_[static_cast<int>(joint)];
  }
  /// Whether every joint has a servo mapping.
  bool HasServos() const;

  /// Whether every joint is within its limits.
  bool WithinLimits(const PopeyeJoints& joints) const;
  /// Throws InvalidArgument naming the first joint outside its limits, its value and range
  /// (in degrees). For commands from users before they reach a motor.
  void CheckLimits(const PopeyeJoints& joints) const;

 private:
  std::string name_;
  HeadGeometry geometry_;
  std::array<JointLimits, 4> limits_;
  geometry::Pose X_WB_;
  geometry::CameraModel left_camera_;
  geometry::CameraModel right_camera_;
  std::array<std::optional<ServoMapping>, 4> servos_;
};

}  // namespace saccade::head
