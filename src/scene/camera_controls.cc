#include "saccade/scene/camera_controls.h"

#include <fmt/format.h>

#include <cmath>

#include "saccade/core/error.h"

namespace saccade::scene {

void CameraControls::Validate(const std::string& what) const {
  if (exposure_s &&
      !(std::isfinite(*exposure_s) && *exposure_s > 0.0 && *exposure_s <= kMaxExposureS)) {
    throw InvalidArgument(fmt::format("{}: exposure_s must be seconds in (0, {}], got {}", what,
                                      kMaxExposureS, *exposure_s));
  }
  if (gain_db && !(std::isfinite(*gain_db) && *gain_db >= 0.0 && *gain_db <= kMaxGainDb)) {
    throw InvalidArgument(
        fmt::format("{}: gain_db must be dB in [0, {}], got {}", what, kMaxGainDb, *gain_db));
  }
  if (focus_m && !(std::isfinite(*focus_m) && *focus_m > 0.0)) {
    throw InvalidArgument(
        fmt::format("{}: focus_m must be a distance in metres > 0, got {}", what, *focus_m));
  }
}

double AppliedControls::GainFactor() const { return std::pow(10.0, gain_db / 20.0); }

double AppliedControls::BrightnessFactor() const {
  if (!commanded) return 1.0;
  const double exposure = exposure_s > 0.0 ? exposure_s : nominal_exposure_s;
  return exposure / nominal_exposure_s * GainFactor();
}

AppliedControls ApplyControls(double file_exposure_s, double file_focus_m,
                              const CameraControls* commanded) {
  AppliedControls applied;
  applied.exposure_s = file_exposure_s;
  applied.focus_m = file_focus_m;
  applied.nominal_exposure_s = file_exposure_s > 0.0 ? file_exposure_s : kNominalExposureS;
  if (commanded == nullptr || commanded->empty()) return applied;
  applied.commanded = true;
  if (commanded->exposure_s) applied.exposure_s = *commanded->exposure_s;
  if (commanded->gain_db) applied.gain_db = *commanded->gain_db;
  if (commanded->focus_m) applied.focus_m = *commanded->focus_m;
  return applied;
}

}  // namespace saccade::scene
