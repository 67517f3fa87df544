#include "saccade/head/head_description.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "core/internal_yaml.h"
#include "head/internal_head_yaml.h"
#include "saccade/core/error.h"
#include "saccade/core/units.h"

namespace saccade::head {
namespace {

// X_WB's rotation must be orthonormal to this (a pose built from rpy is, to ~1e-16).
constexpr double kRotationTolerance = 1e-9;

// A YAML node with its key path and file, so that every error names file, line and key.
using internal::FindAngleEntry;
using internal::GetAngleEntry;
using internal::ReadCamera;
using internal::ReadPose;
using internal::ReadServo;
using saccade::internal::Entry;

HeadGeometry ReadGeometry(const Entry& e) {
  e.ExpectMap({"half_baseline", "D", "H", "delta_left", "delta_right"});
  HeadGeometry g;
  g.B = e.Get("half_baseline").AsPositive();
  const auto optional_length = [&e](const char* key) {
    const auto entry = e.Find(key);
    return entry ? entry->AsDouble() : 0.0;
  };
  g.D = optional_length("D");
  g.H = optional_length("H");
  g.delta_l = optional_length("delta_left");
  g.delta_r = optional_length("delta_right");
  return g;
}

JointLimits ReadJoint(const Entry& e, std::optional<ServoMapping>* servo) {
  e.ExpectMap({"limits", "limits_deg", "max_velocity", "max_velocity_deg", "max_acceleration",
               "max_acceleration_deg", "servo"});
  if (const auto entry = e.Find("servo")) *servo = ReadServo(*entry);
  JointLimits limits;
  bool degrees = false;
  const Entry range = GetAngleEntry(e, "limits", &degrees);
  const double scale_range = degrees ? kDegToRad : 1.0;
  const std::vector<double> values = range.AsDoubles(2);
  if (!(values[0] < values[1])) {
    range.Fail(fmt::format("expected [min, max] with min < max, got [{}, {}] (an empty range)",
                           values[0], values[1]));
  }
  if (values[0] > 0.0 || values[1] < 0.0) {
    range.Fail(fmt::format("expected a range that contains 0 (the joint's home), got [{}, {}]",
                           values[0], values[1]));
  }
  limits.min = values[0] * scale_range;
  limits.max = values[1] * scale_range;
  const Entry velocity = GetAngleEntry(e, "max_velocity", &degrees);
  limits.max_velocity = velocity.AsPositive() * (degrees ? kDegToRad : 1.0);
  const Entry acceleration = GetAngleEntry(e, "max_acceleration", &degrees);
  limits.max_acceleration = acceleration.AsPositive() * (degrees ? kDegToRad : 1.0);
  return limits;
}

HeadDescription ReadHead(const YAML::Node& root, const std::string& file) {
  const Entry top(root, "", &file);
  if (!root.IsMap()) {
    throw FileError(file, top.line(), "",
                    "expected a head description (a map with name, geometry, joints, pose, "
                    "cameras), got " +
                        top.Describe());
  }
  top.ExpectMap({"name", "geometry", "joints", "pose", "cameras"});
  const std::string name = top.Get("name").AsString();
  const HeadGeometry geometry = ReadGeometry(top.Get("geometry"));

  const Entry joints = top.Get("joints");
  joints.ExpectMap({"pan", "tilt", "left", "right"});
  std::array<JointLimits, 4> limits;
  std::array<std::optional<ServoMapping>, 4> servos;
  std::optional<int> servo_line;
  for (const Joint joint : kAllJoints) {
    const Entry entry = joints.Get(JointName(joint));
    limits[static_cast<int>(joint)] = ReadJoint(entry, &servos[static_cast<int>(joint)]);
    if (servos[static_cast<int>(joint)]) {
      for (const Joint other : kAllJoints) {
        if (other == joint) break;
        if (servos[static_cast<int>(other)] &&
            servos[static_cast<int>(other)]->id == servos[static_cast<int>(joint)]->id) {
          entry.Get("servo").Get("id").Fail(fmt::format("servo id {} is already joint {}'s",
                                                        servos[static_cast<int>(joint)]->id,
                                                        JointName(other)));
        }
      }
    }
  }
  const geometry::Pose X_WB = ReadPose(top.Get("pose"));

  const Entry cameras = top.Get("cameras");
  cameras.ExpectMap({"left", "right"});
  const geometry::CameraModel left = ReadCamera(cameras.Get("left"));
  const geometry::CameraModel right = ReadCamera(cameras.Get("right"));
  try {
    return HeadDescription(name, geometry, limits, X_WB, left, right, servos);
  } catch (const InvalidArgument& error) {
    // Every field was checked above; this is a safety net that still names the file.
    throw FileError(file, 0, "", error.what());
  }
}

[[noreturn]] void ThrowInvalid(const std::string& message) {
  throw InvalidArgument("HeadDescription: " + message);
}

}  // namespace

const char* JointName(Joint joint) {
  switch (joint) {
    case Joint::kPan:
      return "pan";
    case Joint::kTilt:
      return "tilt";
    case Joint::kLeft:
      return "left";
    case Joint::kRight:
      return "right";
  }
  return "unknown";
}

double& PopeyeJoints::operator[](Joint joint) {
  SACCADE_ASSERT(static_cast<int>(joint) >= 0 && static_cast<int>(joint) < 4,
                 "PopeyeJoints: invalid joint");
  double PopeyeJoints::*const kMembers[] = {&PopeyeJoints::pan, &PopeyeJoints::tilt,
                                            &PopeyeJoints::left, &PopeyeJoints::right};
  return this->*kMembers[static_cast<int>(joint)];
}

double PopeyeJoints::operator[](Joint joint) const {
  return const_cast<PopeyeJoints&>(*this)[joint];
}

HeadDescription::HeadDescription(std::string name, const HeadGeometry& geometry,
                                 const std::array<JointLimits, 4>& limits,
                                 const geometry::Pose& X_WB,
                                 const geometry::CameraModel& left_camera,
                                 const geometry::CameraModel& right_camera,
                                 const std::array<std::optional<ServoMapping>, 4>& servos)
    : name_(std::move(name)),
      geometry_(geometry),
      limits_(limits),
      X_WB_(X_WB),
      left_camera_(left_camera),
      right_camera_(right_camera),
      servos_(servos) {
  if (!(std::isfinite(geometry.B) && geometry.B > 0.0)) {
    ThrowInvalid(
        fmt::format("geometry.B (half baseline) must be a positive finite length in "
                    "metres, got {}",
                    geometry.B));
  }
  const std::pair<const char*, double> lengths[] = {{"D", geometry.D},
                                                    {"H", geometry.H},
                                                    {"delta_l", geometry.delta_l},
                                                    {"delta_r", geometry.delta_r}};
  for (const auto& [field, value] : lengths) {
    if (!std::isfinite(value)) {
      ThrowInvalid(
          fmt::format("geometry.{} must be a finite length in metres, got {}", field, value));
    }
  }
  for (const Joint joint : kAllJoints) {
    const JointLimits& l = limits_[static_cast<int>(joint)];
    const char* name_j = JointName(joint);
    if (!(std::isfinite(l.min) && std::isfinite(l.max) && l.min < l.max)) {
      ThrowInvalid(fmt::format("joint {}: limits must be finite with min < max, got [{}, {}] rad",
                               name_j, l.min, l.max));
    }
    if (l.min > 0.0 || l.max < 0.0) {
      ThrowInvalid(
          fmt::format("joint {}: limits must contain 0, got [{}, {}] rad", name_j, l.min, l.max));
    }
    if (!(std::isfinite(l.max_velocity) && l.max_velocity > 0.0)) {
      ThrowInvalid(fmt::format("joint {}: max_velocity must be positive and finite, got {} rad/s",
                               name_j, l.max_velocity));
    }
    if (!(std::isfinite(l.max_acceleration) && l.max_acceleration > 0.0)) {
      ThrowInvalid(
          fmt::format("joint {}: max_acceleration must be positive and finite, got {} rad/s^2",
                      name_j, l.max_acceleration));
    }
  }
  for (const Joint joint : kAllJoints) {
    const auto& servo = servos_[static_cast<int>(joint)];
    if (!servo) continue;
    const char* name_j = JointName(joint);
    if (servo->id < 0 || servo->id > 252) {
      ThrowInvalid(fmt::format("joint {}: servo id must be in 0..252, got {}", name_j, servo->id));
    }
    if (servo->direction != 1 && servo->direction != -1) {
      ThrowInvalid(fmt::format("joint {}: servo direction must be 1 or -1, got {}", name_j,
                               servo->direction));
    }
    if (!(std::isfinite(servo->gear_ratio) && servo->gear_ratio > 0.0)) {
      ThrowInvalid(fmt::format("joint {}: servo gear_ratio must be positive and finite, got {}",
                               name_j, servo->gear_ratio));
    }
    if (!std::isfinite(servo->zero_offset)) {
      ThrowInvalid(fmt::format("joint {}: servo zero_offset must be finite, got {}", name_j,
                               servo->zero_offset));
    }
    for (const Joint other : kAllJoints) {
      if (other == joint) break;
      if (servos_[static_cast<int>(other)] && servos_[static_cast<int>(other)]->id == servo->id) {
        ThrowInvalid(fmt::format("joint {}: servo id {} is already joint {}'s", name_j, servo->id,
                                 JointName(other)));
      }
    }
  }
  const Eigen::Matrix3d R = X_WB.linear();
  if (!X_WB.matrix().allFinite() ||
      !(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), kRotationTolerance) ||
      std::abs(R.determinant() - 1.0) > kRotationTolerance) {
    ThrowInvalid("X_WB must be a finite rigid transform (orthonormal rotation, det +1)");
  }
}

HeadDescription HeadDescription::FromYamlFile(const std::filesystem::path& path) {
  return FromYamlString(saccade::internal::ReadConfigFile(path, "head description file"),
                        path.string());
}

HeadDescription HeadDescription::FromYamlString(const std::string& text,
                                                const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    throw FileError(source, error.mark.is_null() ? 0 : error.mark.line + 1, "",
                    "YAML syntax error: " + error.msg);
  }
  try {
    return ReadHead(root, source);
  } catch (const FileError&) {
    throw;
  } catch (const YAML::Exception& error) {
    // Should not happen (every access is checked), but never let a YAML exception escape.
    throw FileError(source, error.mark.is_null() ? 0 : error.mark.line + 1, "", error.msg);
  }
}

bool HeadDescription::HasServos() const {
  for (const auto& servo : servos_) {
    if (!servo) return false;
  }
  return true;
}

bool HeadDescription::WithinLimits(const PopeyeJoints& joints) const {
  for (const Joint joint : kAllJoints) {
    if (!limits(joint).Contains(joints[joint])) return false;
  }
  return true;
}

void HeadDescription::CheckLimits(const PopeyeJoints& joints) const {
  for (const Joint joint : kAllJoints) {
    const JointLimits& l = limits(joint);
    if (!l.Contains(joints[joint])) {
      throw InvalidArgument(fmt::format(
          "HeadDescription::CheckLimits: joint {} = {:.4f} deg is outside its limits "
          "[{:.4f}, {:.4f}] deg",
          JointName(joint), joints[joint] * kRadToDeg, l.min * kRadToDeg, l.max * kRadToDeg));
    }
  }
}

}  // namespace saccade::head
