#include <fmt/ranges.h>

#include <algorithm>
#include <array>
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

namespace {

// A number in (min, max] (`open`) or [min, max]; `what` says what it is.
double ReadEmvaNumber(const Entry& e, double min, double max, bool open, const char* what) {
  const double value = e.AsDouble();
  if (!(open ? value > min : value >= min) || !(value <= max)) {
    e.Fail(fmt::format("expected {} in {}{}, {}], got {}", what, open ? "(" : "[", min, max,
                       e.Describe()));
  }
  return value;
}

// The cross-field rules of EmvaSensor::Validate, each failing at the key that breaks it.
void CheckEmvaTogether(const Entry& e, const EmvaSensor& s) {
  const auto at = [&e](const char* key) { return e.Find(key) ? *e.Find(key) : e; };
  if (!(s.black_level_dn < s.MaxDn())) {
    at(e.Find("black_level_dn") ? "black_level_dn" : "bit_depth")
        .Fail(fmt::format("expected a black level below the largest {}-bit DN ({}), got {} DN",
                          s.bit_depth, s.MaxDn(), s.black_level_dn));
  }
  if (!(s.saturation_e >= kMinDynamicRange * s.dark_noise_e)) {
    at(e.Find("saturation_e") ? "saturation_e" : "dark_noise_e")
        .Fail(fmt::format(
            "expected a saturation of at least {} times the dark noise, got a saturation of {} "
            "e- against a dark noise of {} e-: the saturation lies below the dark level's noise",
            kMinDynamicRange, s.saturation_e, s.dark_noise_e));
  }
  if (!(s.dsnu_e <= s.saturation_e / 10.0)) {
    at(e.Find("dsnu_e") ? "dsnu_e" : "dsnu_dn")
        .Fail(fmt::format("expected a DSNU of at most a tenth of the saturation ({} e-), got {} e-",
                          s.saturation_e / 10.0, s.dsnu_e));
  }
}

}  // namespace

// {preset, quantum_efficiency, gain_dn_per_e, dark_noise_e, saturation_e, dsnu_e | dsnu_dn,
// prnu_percent, bit_depth, black_level_dn, photons_per_second}: an EmvaSensor, the preset's
// figures (if any) replaced by the keys given.
EmvaSensor ReadEmva(const Entry& e) {
  e.ExpectMap(
      {"preset", "quantum_efficiency", "gain_dn_per_e", "dark_noise_e", "saturation_e", "dsnu_e",
       "dsnu_dn", "prnu_percent", "bit_depth", "black_level_dn", "photons_per_second"},
      "an EMVA 1288 sensor {preset, quantum_efficiency, gain_dn_per_e, dark_noise_e, "
      "saturation_e, dsnu_e | dsnu_dn, prnu_percent, bit_depth, black_level_dn, "
      "photons_per_second}");
  EmvaSensor s;
  if (const auto p = e.Find("preset")) {
    const std::optional<EmvaSensor> preset = FindEmvaPreset(p->AsString());
    if (!preset) {
      p->Fail(fmt::format("unknown sensor preset {}; the presets are: {}", p->Describe(),
                          fmt::join(EmvaPresetNames(), ", ")));
    }
    s = *preset;
  }
  if (const auto x = e.Find("quantum_efficiency")) {
    s.quantum_efficiency = ReadEmvaNumber(*x, 0.0, 1.0, true, "a quantum efficiency");
  }
  if (const auto x = e.Find("gain_dn_per_e")) {
    s.gain_dn_per_e = ReadEmvaNumber(*x, 0.0, kMaxGainDnPerE, true, "a gain in DN per electron");
  }
  if (const auto x = e.Find("dark_noise_e")) {
    s.dark_noise_e = ReadEmvaNumber(*x, 0.0, 1000.0, false, "a dark noise in electrons");
  }
  if (const auto x = e.Find("saturation_e")) {
    s.saturation_e = ReadEmvaNumber(*x, 0.0, 1e7, true, "a saturation capacity in electrons");
  }
  const auto dsnu_e = e.Find("dsnu_e");
  const auto dsnu_dn = e.Find("dsnu_dn");
  if (dsnu_e && dsnu_dn) dsnu_dn->Fail("give either 'dsnu_e' (electrons) or 'dsnu_dn', not both");
  if (dsnu_e) s.dsnu_e = ReadEmvaNumber(*dsnu_e, 0.0, 1e6, false, "a DSNU in electrons");
  if (dsnu_dn) {
    s.dsnu_e = ReadEmvaNumber(*dsnu_dn, 0.0, 65535.0, false, "a DSNU in DN") / s.gain_dn_per_e;
  }
  if (const auto x = e.Find("prnu_percent")) {
    s.prnu_percent = ReadEmvaNumber(*x, 0.0, 20.0, false, "a PRNU in percent");
  }
  if (const auto x = e.Find("bit_depth")) s.bit_depth = static_cast<int>(x->AsInteger(8, 16));
  if (const auto x = e.Find("black_level_dn")) {
    s.black_level_dn = ReadEmvaNumber(*x, 0.0, 65535.0, false, "a black level in DN");
  }
  if (const auto x = e.Find("photons_per_second")) {
    s.photons_per_second = ReadEmvaNumber(*x, 0.0, 1e12, true, "photons per second");
  }
  CheckEmvaTogether(e, s);
  return s;
}

namespace {

// A name of `names` (lower case), the index of the name in it; fails naming the names.
template <class Enum, std::size_t N>
Enum ReadName(const Entry& e, const std::array<const char*, N>& names, const char* what) {
  const std::string text = e.AsString();
  for (std::size_t i = 0; i < N; ++i) {
    if (text == names[i]) return static_cast<Enum>(i);
  }
  e.Fail(fmt::format("expected {} ({}), got {}", what, fmt::join(names, ", "), e.Describe()));
}

// A finite number > 0 (at most `max`); `what` says what it is.
double ReadPositiveAtMost(const Entry& e, double max, const char* what) {
  const double value = e.AsDouble();
  if (!(value > 0.0 && value <= max)) {
    e.Fail(fmt::format("expected {} in (0, {}], got {}", what, max, e.Describe()));
  }
  return value;
}

constexpr double kMaxColorGain = 16.0;
constexpr double kMaxGamma = 10.0;

}  // namespace

// {cfa, demosaic, white_balance: {red, green, blue}, tone_curve: linear | srgb | {gamma}}.
ColorSpec ReadColor(const Entry& e) {
  e.ExpectMap({"cfa", "demosaic", "white_balance", "tone_curve"},
              "a sensor's colour {cfa, demosaic, white_balance, tone_curve}");
  ColorSpec color;
  if (const auto x = e.Find("cfa")) {
    color.cfa =
        ReadName<CfaPattern>(*x, std::array<const char*, 5>{"none", "rggb", "bggr", "grbg", "gbrg"},
                             "a colour filter pattern");
  }
  if (const auto x = e.Find("demosaic")) {
    color.demosaic = ReadName<DemosaicMethod>(
        *x, std::array<const char*, 2>{"bilinear", "edge_aware"}, "a demosaicing method");
  }
  if (const auto wb = e.Find("white_balance")) {
    wb->ExpectMap({"red", "green", "blue"}, "white balance gains {red, green, blue}");
    const char* keys[3] = {"red", "green", "blue"};
    for (int c = 0; c < 3; ++c) {
      if (const auto gain = wb->Find(keys[c])) {
        color.white_balance[c] = ReadPositiveAtMost(*gain, kMaxColorGain, "a gain");
      }
    }
  }
  if (const auto tone = e.Find("tone_curve")) {
    if (tone->IsMap()) {
      tone->ExpectMap({"gamma"}, "a tone curve {gamma}");
      color.tone_curve = ToneCurveKind::kGamma;
      color.gamma = ReadPositiveAtMost(tone->Get("gamma"), kMaxGamma, "a display gamma");
    } else {
      color.tone_curve =
          ReadName<ToneCurveKind>(*tone, std::array<const char*, 3>{"linear", "gamma", "srgb"},
                                  "a tone curve (or {gamma: 2.2})");
    }
  }
  return color;
}

// {vignetting: cos4 | {polynomial: [a1, a2, a3]}, f_number, focal_length_mm, focus_distance,
// pixel_pitch_um, max_coc_px}: LensSpec. Depth of field with f_number, which needs
// focal_length_mm and focus_distance.
LensSpec ReadLens(const Entry& e) {
  e.ExpectMap({"vignetting", "f_number", "focal_length_mm", "focus_distance", "pixel_pitch_um",
               "max_coc_px"},
              "a lens {vignetting, f_number, focal_length_mm, focus_distance, pixel_pitch_um, "
              "max_coc_px}");
  LensSpec lens;
  if (const auto v = e.Find("vignetting")) {
    if (v->IsMap()) {
      v->ExpectMap({"polynomial"}, "a vignetting model (cos4, none or {polynomial: [a1, a2, a3]})");
      const Entry poly = v->Get("polynomial");
      const std::vector<double> a = poly.AsDoubles(3, "[a1, a2, a3]");
      lens.vignetting = VignettingModel::kPolynomial;
      lens.vignetting_coefficients = {a[0], a[1], a[2]};
      // Relative illumination 1 + a1 r^2 + a2 r^4 + a3 r^6 must stay >= 0 on r in [0, 1].
      for (int i = 0; i <= 1000; ++i) {
        const double r2 = (i / 1000.0) * (i / 1000.0);
        const double f = 1.0 + r2 * (a[0] + r2 * (a[1] + r2 * a[2]));
        if (!(f >= 0.0)) {
          poly.Fail(fmt::format(
              "expected a relative illumination 1 + a1 r^2 + a2 r^4 + a3 r^6 >= 0 for r in "
              "[0, 1], got {} at r = {}",
              f, i / 1000.0));
        }
      }
    } else {
      lens.vignetting =
          ReadName<VignettingModel>(*v, std::array<const char*, 2>{"none", "cos4"},
                                    "a vignetting model (or {polynomial: [a1, a2, a3]})");
    }
  }
  const auto n = e.Find("f_number");
  const auto f = e.Find("focal_length_mm");
  const auto s = e.Find("focus_distance");
  for (const auto& other : {f, s, e.Find("pixel_pitch_um"), e.Find("max_coc_px")}) {
    if (other && !n) other->Fail("depth of field needs the lens's 'f_number'");
  }
  if (!n) return lens;
  lens.f_number = ReadPositiveAtMost(*n, 1000.0, "an f-number");
  if (!f) n->Fail("depth of field needs the lens's 'focal_length_mm'");
  if (!s) n->Fail("depth of field needs the lens's 'focus_distance' (metres)");
  lens.focal_length_m = ReadPositiveAtMost(*f, 1000.0, "a focal length in millimetres") / 1e3;
  lens.focus_distance_m = s->AsDouble();
  if (!(lens.focus_distance_m > lens.focal_length_m && lens.focus_distance_m <= 1e6)) {
    s->Fail(
        fmt::format("expected a focus distance in metres beyond the focal length ({} m), "
                    "at most 1e6, got {}",
                    lens.focal_length_m, s->Describe()));
  }
  if (const auto x = e.Find("pixel_pitch_um")) {
    lens.pixel_pitch_m = ReadInRange(*x, 1000.0, "a pixel pitch in micrometres") / 1e6;
  }
  if (const auto x = e.Find("max_coc_px")) {
    lens.max_coc_px = x->AsDouble();
    if (!(lens.max_coc_px >= 1.0 && lens.max_coc_px <= 256.0)) {
      x->Fail(fmt::format("expected a largest circle of confusion in pixels in [1, 256], got {}",
                          x->Describe()));
    }
  }
  return lens;
}

// {exposure | exposure_ms, blur_samples, read_noise_dn, gain_dn_per_e, seed, emva, color}:
// SensorSpec.
SensorSpec ReadSensor(const Entry& e) {
  e.ExpectMap({"exposure", "exposure_ms", "blur_samples", "read_noise_dn", "gain_dn_per_e", "seed",
               "emva", "color"},
              "a sensor {exposure | exposure_ms, blur_samples, read_noise_dn, gain_dn_per_e, "
              "seed, emva, color}");
  SensorSpec sensor;
  if (const auto c = e.Find("color")) sensor.color = ReadColor(*c);
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
  if (const auto x = e.Find("emva")) {
    sensor.emva = ReadEmva(*x);
    if (sensor.HasNoise()) {
      (e.Find("read_noise_dn") ? *e.Find("read_noise_dn") : *e.Find("gain_dn_per_e"))
          .Fail(
              "give either the noise figures (read_noise_dn, gain_dn_per_e) or an emva sensor, not "
              "both");
    }
    if (!(sensor.exposure > 0.0)) {
      x->Fail(
          "an emva sensor needs an exposure > 0 (photons = photons_per_second x exposure): give "
          "the sensor's 'exposure' or 'exposure_ms'");
    }
  }
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
