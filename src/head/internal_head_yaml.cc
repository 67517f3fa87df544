#include "head/internal_head_yaml.h"

#include <fmt/format.h>

#include <cmath>

#include "saccade/core/error.h"
#include "saccade/core/units.h"

namespace saccade::head::internal {

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

std::optional<double> FindAngle(const Entry& parent, const std::string& key) {
  bool degrees = false;
  const auto entry = FindAngleEntry(parent, key, &degrees);
  if (!entry) return std::nullopt;
  return entry->AsDouble() * (degrees ? kDegToRad : 1.0);
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

geometry::CameraModel ReadCamera(const Entry& e, const std::vector<std::string>& extra_keys) {
  std::vector<std::string> keys = {
      "width", "height", "focal_length_mm", "pixel_size_um", "fx", "fy", "cx",
      "cy",    "skew",   "distortion"};
  keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
  e.ExpectMap(keys);
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

}  // namespace saccade::head::internal
