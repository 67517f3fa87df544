#include "saccade/scene/emva_sensor.h"

#include <fmt/format.h>

#include <cmath>

#include "saccade/core/error.h"

namespace saccade::scene {
namespace {

// Data-sheet presets. The figures are rounded values of the kind published in EMVA 1288
// reports of cameras with these Sony Pregius sensors (eta at the green peak, sigma_d,
// mu_e.sat); DSNU and PRNU are typical magnitudes, not one report's. K and the black level
// are chosen so that the full well fits the 12-bit range, as a camera's default gain does;
// photons_per_second puts a full-white pixel at about 80 % of the full well at 10 ms.
struct Preset {
  const char* name;
  EmvaSensor sensor;
};

EmvaSensor MakePreset(double eta, double K, double sigma_d, double sat, double dsnu, double prnu,
                      double photons, const char* name) {
  EmvaSensor s;
  s.quantum_efficiency = eta;
  s.gain_dn_per_e = K;
  s.dark_noise_e = sigma_d;
  s.saturation_e = sat;
  s.dsnu_e = dsnu;
  s.prnu_percent = prnu;
  s.bit_depth = 12;
  s.black_level_dn = 64.0;
  s.photons_per_second = photons;
  s.preset = name;
  return s;
}

const std::vector<Preset>& Presets() {
  static const std::vector<Preset> presets = {
      // Sony IMX174 (1/1.2", 5.86 um): eta ~ 0.76, sigma_d ~ 6.8 e-, mu_e.sat ~ 32 ke-.
      {"imx174", MakePreset(0.76, 0.12, 6.8, 32000.0, 3.0, 0.6, 3.4e6, "imx174")},
      // Sony IMX264 (2/3", 3.45 um): eta ~ 0.70, sigma_d ~ 2.3 e-, mu_e.sat ~ 10.5 ke-.
      {"imx264", MakePreset(0.70, 0.36, 2.3, 10500.0, 1.0, 0.5, 1.2e6, "imx264")},
  };
  return presets;
}

void CheckRange(const char* field, double value, double min, double max, bool min_open,
                const char* what) {
  const bool above = min_open ? value > min : value >= min;
  if (!(std::isfinite(value) && above && value <= max)) {
    throw InvalidArgument(fmt::format("EmvaSensor: {} must be {} in {}{}, {}], got {}", field, what,
                                      min_open ? "(" : "[", min, max, value));
  }
}

}  // namespace

double EmvaSensor::MaxDn() const { return std::ldexp(1.0, bit_depth) - 1.0; }

void EmvaSensor::Validate() const {
  CheckRange("quantum_efficiency", quantum_efficiency, 0.0, 1.0, true, "electrons per photon");
  CheckRange("gain_dn_per_e", gain_dn_per_e, 0.0, 64.0, true, "a gain in DN per electron");
  CheckRange("dark_noise_e", dark_noise_e, 0.0, 1000.0, false, "electrons");
  CheckRange("saturation_e", saturation_e, 0.0, 1e7, true, "electrons");
  CheckRange("dsnu_e", dsnu_e, 0.0, saturation_e / 10.0, false,
             "electrons (a tenth of saturation)");
  CheckRange("prnu_percent", prnu_percent, 0.0, 20.0, false, "percent");
  if (bit_depth < 8 || bit_depth > 16) {
    throw InvalidArgument(
        fmt::format("EmvaSensor: bit_depth must be in [8, 16], got {}", bit_depth));
  }
  if (!(std::isfinite(black_level_dn) && black_level_dn >= 0.0 && black_level_dn < MaxDn())) {
    throw InvalidArgument(fmt::format(
        "EmvaSensor: black_level_dn must be in [0, {}) (below the largest {}-bit DN), got {}",
        MaxDn(), bit_depth, black_level_dn));
  }
  CheckRange("photons_per_second", photons_per_second, 0.0, 1e12, true, "photons per second");
  if (!(saturation_e >= kMinDynamicRange * dark_noise_e)) {
    throw InvalidArgument(fmt::format(
        "EmvaSensor: saturation_e ({} e-) must be at least {} times the dark noise ({} e-): the "
        "saturation lies within the dark level's noise",
        saturation_e, kMinDynamicRange, dark_noise_e));
  }
}

std::optional<EmvaSensor> FindEmvaPreset(const std::string& name) {
  for (const Preset& p : Presets()) {
    if (name == p.name) return p.sensor;
  }
  return std::nullopt;
}

std::vector<std::string> EmvaPresetNames() {
  std::vector<std::string> names;
  for (const Preset& p : Presets()) names.emplace_back(p.name);
  return names;
}

EmvaSensor EmvaFromLegacyNoise(double read_noise_dn, double gain_dn_per_e, double exposure_s) {
  if (!(gain_dn_per_e > 0.0)) {
    throw InvalidArgument(
        "EmvaFromLegacyNoise: gain_dn_per_e is 0 (no shot noise), which has no EMVA 1288 form");
  }
  if (!(exposure_s > 0.0)) {
    throw InvalidArgument(
        fmt::format("EmvaFromLegacyNoise: exposure must be > 0 s, got {}", exposure_s));
  }
  EmvaSensor s;
  s.quantum_efficiency = 1.0;
  s.gain_dn_per_e = gain_dn_per_e;
  s.dark_noise_e = read_noise_dn / gain_dn_per_e;
  s.saturation_e = 255.0 / gain_dn_per_e;
  s.bit_depth = 8;
  s.photons_per_second = 255.0 / gain_dn_per_e / exposure_s;
  s.preset = "legacy";
  return s;
}

}  // namespace saccade::scene
