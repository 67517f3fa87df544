#include <algorithm>
#include <cmath>

#include "internal_scene_entries.h"
#include "saccade/core/error.h"
#include "saccade/scene/limits.h"

namespace saccade::scene::internal_reader {

void CheckCameraName(const Entry& e, const std::string& name,
                     std::map<std::string, std::string>& names) {
  const bool safe = std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
  if (!safe || name == "." || name == "..") {
    e.Fail(
        "expected a camera name of letters, digits, '_', '-' and '.' (it names output "
        "folders), got " +
        e.Describe());
  }
  if (const auto [it, inserted] = names.emplace(name, e.path()); !inserted) {
    e.Fail(fmt::format("duplicate camera name '{}' (also {})", name, it->second));
  }
}

geometry::ClipPlanes ReadClip(const Entry& e) {
  e.ExpectMap({"near", "far"}, "clip planes {near, far}");
  geometry::ClipPlanes clip{kDefaultNear, kDefaultFar};
  if (const auto n = e.Find("near")) clip.near = n->AsPositive();
  if (const auto f = e.Find("far")) clip.far = f->AsPositive();
  if (!(clip.near < clip.far)) {
    (e.Find("far") ? *e.Find("far") : *e.Find("near"))
        .Fail(fmt::format("expected near < far, got near {} m and far {} m", clip.near, clip.far));
  }
  return clip;
}

// A number in [0, max]; `what` says what it is ("an exposure in seconds").
double ReadInRange(const Entry& e, double max, const char* what) {
  const double value = e.AsDouble();
  if (!(value >= 0.0 && value <= max)) {
    e.Fail(fmt::format("expected {} in [0, {}], got {}", what, max, e.Describe()));
  }
  return value;
}

// {exposure | exposure_ms, blur_samples, read_noise_dn, gain_dn_per_e, seed}: SensorSpec.
SensorSpec ReadSensor(const Entry& e) {
  e.ExpectMap({"exposure", "exposure_ms", "blur_samples", "read_noise_dn", "gain_dn_per_e", "seed"},
              "a sensor {exposure | exposure_ms, blur_samples, read_noise_dn, gain_dn_per_e, "
              "seed}");
  SensorSpec sensor;
  const auto seconds = e.Find("exposure");
  const auto ms = e.Find("exposure_ms");
  if (seconds && ms) {
    ms->Fail("give either 'exposure' (seconds) or 'exposure_ms', not both");
  }
  if (seconds) sensor.exposure = ReadInRange(*seconds, kMaxExposure, "an exposure in seconds");
  if (ms) {
    sensor.exposure = ReadInRange(*ms, kMaxExposure * 1e3, "an exposure in milliseconds") / 1e3;
  }
  if (const auto n = e.Find("blur_samples")) {
    sensor.blur_samples = static_cast<int>(n->AsInteger(1, kMaxBlurSamples));
  }
  if (const auto x = e.Find("read_noise_dn")) {
    sensor.read_noise_dn = ReadInRange(*x, kMaxNoiseDn, "a standard deviation in DN");
  }
  if (const auto x = e.Find("gain_dn_per_e")) {
    sensor.gain_dn_per_e = ReadInRange(*x, kMaxGainDnPerE, "a gain in DN per electron");
  }
  if (const auto x = e.Find("seed")) sensor.seed = x->AsUint64();
  try {
    sensor.Validate();  // a safety net: every range was checked above, with its line
  } catch (const InvalidArgument& error) {
    e.Fail(error.what());
  }
  return sensor;
}

// The optical frame (x right, y down, z forward) at `eye` looking at `target`.
geometry::Pose ReadLookAt(const Entry& e) {
  e.ExpectMap({"eye", "target", "up"}, "a look_at {eye, target, up}");
  const Eigen::Vector3d eye = ToEigen(e.Get("eye").AsVector3());
  const Entry target_entry = e.Get("target");
  const Eigen::Vector3d target = ToEigen(target_entry.AsVector3());
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const auto up_entry = e.Find("up");
  if (up_entry) up = ToEigen(up_entry->AsVector3());
  const Eigen::Vector3d forward = target - eye;
  if (!(forward.norm() > 0.0) || !forward.allFinite()) {
    target_entry.Fail("expected a target apart from the eye");
  }
  const Eigen::Vector3d z = forward.normalized();
  if (!(up.norm() > 0.0) || !(z.cross(up.normalized()).norm() > kMinUpSine)) {
    (up_entry ? *up_entry : e)
        .Fail("expected an up direction not parallel to the viewing direction (eye to target)");
  }
  const Eigen::Vector3d x = z.cross(up).normalized();  // right
  const Eigen::Vector3d y = z.cross(x);                // down
  Eigen::Matrix3d R;
  R << x, y, z;
  return geometry::MakePose(R, eye);
}

// A camera's image against the renderer's largest image and memory budget (scene/limits.h),
// before anything is allocated for it; `where` is its calibration (or the head file).
void CheckImageBudget(const CameraSpec& camera, const Entry& where) {
  const int w = camera.model.intrinsics().width();
  const int h = camera.model.intrinsics().height();
  if (w > kMaxImageSide || h > kMaxImageSide) {
    where.Fail(
        fmt::format("camera '{}' is {}x{} px: a side above {} px, the largest image "
                    "saccade renders",
                    camera.name, w, h, kMaxImageSide));
  }
  if (int64_t{w} * h > kMaxImagePixels) {
    where.Fail(
        fmt::format("camera '{}' is {}x{} px = {:.1f} Mpx, more than the {:.0f} Mpx a "
                    "camera may have (its render targets take up to 64 bytes a pixel)",
                    camera.name, w, h, int64_t{w} * h * 1e-6, kMaxImagePixels * 1e-6));
  }
}

// Explicit ids first (unique), then the smallest free ids in file order, the robot last.
void AssignIds(std::vector<Object>& objects, const std::vector<std::optional<Entry>>& id_entries,
               Robot* robot, const std::optional<Entry>& robot_id_entry) {
  std::map<uint32_t, std::string> used;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].id == 0) continue;
    const std::string owner = fmt::format("objects[{}] '{}'", i, objects[i].name);
    if (const auto [it, inserted] = used.emplace(objects[i].id, owner); !inserted) {
      id_entries[i]->Fail(fmt::format("duplicate id {} (also {})", objects[i].id, it->second));
    }
  }
  if (robot != nullptr && robot->id != 0) {
    if (const auto [it, inserted] = used.emplace(robot->id, "robot"); !inserted) {
      robot_id_entry->Fail(fmt::format("duplicate id {} (also {})", robot->id, it->second));
    }
  }
  uint32_t next = 1;
  const auto take = [&used, &next](const std::string& owner) {
    while (used.count(next) != 0) ++next;
    used.emplace(next, owner);
    return next;
  };
  for (Object& object : objects) {
    if (object.id == 0) object.id = take(object.name);
  }
  if (robot != nullptr && robot->id == 0) robot->id = take("robot");
}

}  // namespace saccade::scene::internal_reader
