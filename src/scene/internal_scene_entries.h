#pragma once
// Reading the scene file's values (private to scene_loader.cc and its helpers): poses, sizes,
// colours, a camera's clip planes, sensor and look-at, camera names, the image budget, and
// instance ids. Each failure is the entry's FileError "file:line: key: what".
#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/internal_yaml.h"
#include "saccade/core/units.h"
#include "saccade/scene/scene.h"

namespace saccade::scene::internal_reader {

using saccade::internal::Entry;

// Instance ids stay exact in a float (2^24) for renderers that pass them through one.
inline constexpr int64_t kMaxId = (int64_t{1} << 24) - 1;
// Default clip planes of every camera (metres): the robot's body is built for near = 0.05.
inline constexpr double kDefaultNear = 0.05;
inline constexpr double kDefaultFar = 50.0;
// Files a scene refers to (models, images, calibrations) larger than this are refused.
inline constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{4} << 30;
// A picture's side (metres): far beyond any scene, and within a float's range (1e6 m a side).
inline constexpr double kMaxPictureSide = 1e6;
// A look_at `up` within this sine of the viewing direction leaves the roll undefined.
inline constexpr double kMinUpSine = 1e-6;
// Sensor ranges: the same as SensorSpec::Validate's (scene.h), checked here with the line.
inline constexpr double kMaxExposure = 1.0;  // seconds
inline constexpr int kMaxBlurSamples = 64;
inline constexpr double kMaxNoiseDn = 64.0;  // read noise, DN
inline constexpr double kMaxGainDnPerE = 64.0;

// The YAML reader (core) has no Eigen: its fixed-size arrays become Eigen vectors here.
inline Eigen::Vector3d ToEigen(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }
inline Eigen::Vector4f ToEigen(const std::array<float, 4>& v) { return {v[0], v[1], v[2], v[3]}; }

inline const Eigen::Vector4f kDefaultPrimitiveColor(0.7f, 0.7f, 0.7f, 1.0f);

// An angle triple given as `<key>_deg` (degrees) or `<key>` (radians): at most one of them.
inline std::optional<Eigen::Vector3d> FindAngles(const Entry& parent, const std::string& key,
                                                 const char* names) {
  const std::string deg_key = key + "_deg";
  const auto rad = parent.Find(key.c_str());
  const auto deg = parent.Find(deg_key.c_str());
  if (rad && deg) deg->Fail("give either '" + key + "' (radians) or '" + deg_key + "', not both");
  if (deg) return ToEigen(deg->AsVector3(names)) * kDegToRad;
  if (rad) return ToEigen(rad->AsVector3(names));
  return std::nullopt;
}

inline geometry::Pose PoseFrom(const Eigen::Vector3d& position, const Eigen::Vector3d& rpy) {
  return geometry::MakePose(geometry::RotationFromRpy(rpy.x(), rpy.y(), rpy.z()), position);
}

// {position, rpy | rpy_deg}; rpy defaults to 0.
inline geometry::Pose ReadPose(const Entry& e) {
  e.ExpectMap({"position", "rpy", "rpy_deg"}, "a pose {position, rpy_deg}");
  const Eigen::Vector3d position = ToEigen(e.Get("position").AsVector3());
  const Eigen::Vector3d rpy =
      FindAngles(e, "rpy", "[roll, pitch, yaw]").value_or(Eigen::Vector3d::Zero());
  return PoseFrom(position, rpy);
}

// A positive number (uniform) or `n` positive numbers.
inline Eigen::Vector3d ReadPositiveSizes(const Entry& e, int n, const char* names) {
  const std::string expected =
      fmt::format("expected a positive number or {} positive numbers {}", n, names);
  Eigen::Vector3d out = Eigen::Vector3d::Ones();
  if (e.IsScalar()) {
    out.head(n).setConstant(e.AsPositive());
    return out;
  }
  if (!e.IsSequence() || static_cast<int>(e.node().size()) != n) {
    e.Fail(fmt::format("{}, got {}", expected,
                       e.IsSequence() ? fmt::format("{} numbers", e.node().size()) : e.Describe()));
  }
  for (int i = 0; i < n; ++i) {
    const Entry item(e.node()[i], fmt::format("{}[{}]", e.path(), i), &e.file(), e.line());
    out[i] = item.AsPositive();
  }
  return out;
}

inline Eigen::Vector3f Rgb(const Eigen::Vector4f& rgba) { return rgba.head<3>(); }

void CheckCameraName(const Entry& e, const std::string& name,
                     std::map<std::string, std::string>& names);

geometry::ClipPlanes ReadClip(const Entry& e);

// A number in [0, max]; `what` says what it is ("an exposure in seconds").
double ReadInRange(const Entry& e, double max, const char* what);

// {preset, quantum_efficiency, gain_dn_per_e, ...}: an EMVA 1288 sensor (a sensor's `emva`).
EmvaSensor ReadEmva(const Entry& e);

// {cfa, demosaic, white_balance, tone_curve}: a sensor's colour (camera_optics.h).
ColorSpec ReadColor(const Entry& e);

// {vignetting, f_number, focal_length_mm, focus_distance, pixel_pitch_um, max_coc_px}: a
// camera's lens (camera_optics.h).
LensSpec ReadLens(const Entry& e);

// {exposure | exposure_ms, blur_samples, read_noise_dn, gain_dn_per_e, seed, emva, color}:
// SensorSpec.
SensorSpec ReadSensor(const Entry& e);

// The optical frame (x right, y down, z forward) at `eye` looking at `target`.
geometry::Pose ReadLookAt(const Entry& e);

// A camera's image against the renderer's largest image and memory budget (scene/limits.h),
// before anything is allocated for it; `where` is its calibration (or the head file).
void CheckImageBudget(const CameraSpec& camera, const Entry& where);

// Explicit ids first (unique), then the smallest free ids in file order, the robot last.
void AssignIds(std::vector<Object>& objects, const std::vector<std::optional<Entry>>& id_entries,
               Robot* robot, const std::optional<Entry>& robot_id_entry);

}  // namespace saccade::scene::internal_reader
