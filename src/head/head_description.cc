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
#include "saccade/core/error.h"
#include "saccade/core/units.h"

namespace saccade::head {
namespace {

// X_WB's rotation must be orthonormal to this (a pose built from rpy is, to ~1e-16).
constexpr double kRotationTolerance = 1e-9;

// A YAML node with its key path and file, so that every error names file, line and key.
using saccade::internal::Entry;

// An angle given either as `<key>_deg` (degrees) or `<key>` (radians): exactly one of them.
std::optional<Entry> FindAngleEntry(const Entry& parent, const std::string& key, bool* degrees) {
  const std::string deg_key = key + "_deg";
  const auto rad = parent.Find(key.c_str());
  const auto deg = parent.Find(deg_key.c_str());
  if (rad && deg) rad->Fail("give either '" + key + "' (radians) or '" + deg_key + "', not both");
  *degrees = deg.has_value();
  return deg ? deg : rad;
}
Entry GetAngleEntry(const Entry& parent, const std::string& key, bool* degrees) {
  auto entry = FindAngleEntry(parent, key, degrees);
  if (!entry) parent.Fail("missing key '" + key + "_deg' (degrees) or '" + key + "' (radians)");
  return *entry;
}

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

ServoMapping ReadServo(const Entry& e) {
  e.ExpectMap({"id", "zero_offset", "zero_offset_deg", "direction", "gear_ratio"});
  ServoMapping servo;
  const Entry id = e.Get("id");
  const double id_value = id.AsDouble();
  if (!(id_value >= 0 && id_value <= 252 && id_value == std::floor(id_value))) {
    id.Fail(fmt::format("expected a servo id, an integer in 0..252, got {}", id.Describe()));
  }
  servo.id = static_cast<int>(id_value);
  bool degrees = false;
  if (const auto offset = FindAngleEntry(e, "zero_offset", &degrees)) {
    servo.zero_offset = offset->AsDouble() * (degrees ? kDegToRad : 1.0);
  }
  if (const auto direction = e.Find("direction")) {
    const double value = direction->AsDouble();
    if (value != 1.0 && value != -1.0) {
      direction->Fail("expected 1 or -1, got " + direction->Describe());
    }
    servo.direction = static_cast<int>(value);
  }
  if (const auto ratio = e.Find("gear_ratio")) servo.gear_ratio = ratio->AsPositive();
  return servo;
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

geometry::Pose ReadPose(const Entry& e) {
  e.ExpectMap({"position", "rpy", "rpy_deg"});
  const std::vector<double> position = e.Get("position").AsDoubles(3);
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  bool degrees = false;
  if (const auto entry = FindAngleEntry(e, "rpy", &degrees)) {
    const std::vector<double> values = entry->AsDoubles(3);
    rpy = Eigen::Vector3d(values[0], values[1], values[2]) * (degrees ? kDegToRad : 1.0);
  }
  return geometry::MakePose(geometry::RotationFromRpy(rpy.x(), rpy.y(), rpy.z()),
                            Eigen::Vector3d(position[0], position[1], position[2]));
}

geometry::CameraModel ReadCamera(const Entry& e) {
  e.ExpectMap({"width", "height", "focal_length_mm", "pixel_size_um", "fx", "fy", "cx", "cy",
               "skew", "distortion"});
  const int width = static_cast<int>(e.Get("width").AsInteger(1, 1000000));
  const int height = static_cast<int>(e.Get("height").AsInteger(1, 1000000));
  double fx = 0.0;
  double fy = 0.0;
  const bool physical = e.Has("focal_length_mm") || e.Has("pixel_size_um");
  if (physical) {
    for (const char* key : {"fx", "fy"}) {
      if (const auto entry = e.Find(key)) {
        entry->Fail(std::string("give either focal_length_mm and pixel_size_um, or fx and fy, "
                                "not both ('") +
                    key + "' given with focal_length_mm/pixel_size_um)");
      }
    }
    const double focal_mm = e.Get("focal_length_mm").AsPositive();
    const double pixel_um = e.Get("pixel_size_um").AsPositive();
    fx = fy = focal_mm / (pixel_um * 1e-3);  // both in millimetres
  } else {
    if (!e.Has("fx") && !e.Has("fy")) {
      e.Fail(
          "missing the focal length: give fx and fy (pixels), or focal_length_mm and "
          "pixel_size_um");
    }
    fx = e.Get("fx").AsPositive();
    fy = e.Get("fy").AsPositive();
  }
  // Default principal point: the image centre with pixel centres at integer coordinates.
  const auto cx_entry = e.Find("cx");
  const auto cy_entry = e.Find("cy");
  const double cx = cx_entry ? cx_entry->AsDouble() : 0.5 * (width - 1);
  const double cy = cy_entry ? cy_entry->AsDouble() : 0.5 * (height - 1);
  const auto skew_entry = e.Find("skew");
  const double skew = skew_entry ? skew_entry->AsDouble() : 0.0;

  geometry::Distortion distortion;
  if (const auto d = e.Find("distortion")) {
    d->ExpectMap({"model", "coefficients"});
    const Entry model_entry = d->Get("model");
    const std::string model_name = model_entry.AsString();
    geometry::DistortionModel model = geometry::DistortionModel::kNone;
    if (model_name == "radtan") {
      model = geometry::DistortionModel::kRadialTangential;
    } else if (model_name == "fisheye") {
      model = geometry::DistortionModel::kFisheye;
    } else if (model_name != "none") {
      model_entry.Fail("expected 'none', 'radtan' or 'fisheye', got '" + model_name + "'");
    }
    const auto coefficients_entry = d->Find("coefficients");
    std::vector<double> coefficients;
    if (coefficients_entry) coefficients = coefficients_entry->AsDoubles(-1);
    try {
      distortion = geometry::Distortion::FromCoefficients(model, coefficients);
    } catch (const InvalidArgument& error) {
      (coefficients_entry ? *coefficients_entry : model_entry).Fail(error.what());
    }
  }
  try {
    return geometry::CameraModel(geometry::Intrinsics(width, height, fx, fy, cx, cy, skew),
                                 distortion);
  } catch (const InvalidArgument& error) {
    e.Fail(error.what());
  }
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

double& JointState::operator[](Joint joint) {
  SACCADE_ASSERT(static_cast<int>(joint) >= 0 && static_cast<int>(joint) < 4,
                 "JointState: invalid joint");
  double JointState::*const kMembers[] = {&JointState::pan, &JointState::tilt, &JointState::left,
                                          &JointState::right};
  return this->*kMembers[static_cast<int>(joint)];
}

double JointState::operator[](Joint joint) const { return const_cast<JointState&>(*this)[joint]; }

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

bool HeadDescription::WithinLimits(const JointState& joints) const {
  for (const Joint joint : kAllJoints) {
    if (!limits(joint).Contains(joints[joint])) return false;
  }
  return true;
}

void HeadDescription::CheckLimits(const JointState& joints) const {
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
