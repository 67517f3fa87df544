#pragma once
// A camera's per-frame controls, as a machine-vision camera exposes them: exposure time, gain
// and focus distance. A pipeline commands them (sim.cameras' `controls` input, or
// scene::SceneState::camera_controls directly); the renderer applies them to the frame and
// stamps the values used into its metadata (ImageMetadata::exposure_s, gain_db, focus_m).
// docs/sensor.md ("Exposure, gain and focus") describes what each does to the pixels.
//
// A control that is absent keeps the file's value: SensorSpec::exposure, a gain of 0 dB, the
// lens's focus distance (none when the camera has no lens that focuses).

#include <optional>
#include <string>

namespace saccade::scene {

/// The largest exposure time a command may ask for, seconds.
inline constexpr double kMaxExposureS = 1.0;
/// The largest gain a command may ask for, dB (machine-vision cameras go to 24..48 dB).
inline constexpr double kMaxGainDb = 48.0;
/// The nominal exposure of a camera whose file gives none (SensorSpec::exposure 0): what its
/// rendered brightness stands for, so that a commanded exposure still scales it.
inline constexpr double kNominalExposureS = 0.01;

/// Commanded controls of one camera; each absent one keeps the file's value.
struct CameraControls {
  std::optional<double> exposure_s;  ///< exposure time, seconds, in (0, kMaxExposureS]
  std::optional<double> gain_db;     ///< gain, dB, in [0, kMaxGainDb]; linear 10^(dB / 20)
  std::optional<double> focus_m;     ///< focus distance, metres, > 0 and finite

  bool empty() const { return !exposure_s && !gain_db && !focus_m; }
  /// Throws InvalidArgument "<what>: exposure_s must be seconds in (0, 1], got 0" and the like
  /// when a value is out of range; `what` names where the values came from.
  void Validate(const std::string& what) const;
};

/// The controls a frame is taken with: the commanded values, else the file's.
struct AppliedControls {
  double exposure_s = 0.0;  ///< 0: an instant (the file's exposure 0, no command)
  double gain_db = 0.0;
  double focus_m = 0.0;  ///< 0: no focus distance (no command, no lens that focuses)
  /// What the rendered brightness stands for: the file's exposure, or kNominalExposureS.
  double nominal_exposure_s = kNominalExposureS;
  /// Whether any control was commanded (else the frame renders exactly as the file says).
  bool commanded = false;

  /// The gain as a factor, 10^(gain_db / 20).
  double GainFactor() const;
  /// The brightness of the frame relative to the file's without an EMVA sensor:
  /// (exposure or nominal) / nominal * GainFactor(); exactly 1 when nothing is commanded.
  double BrightnessFactor() const;
};

/// The controls of a camera whose file exposure is `file_exposure_s` (>= 0) and whose lens
/// focuses at `file_focus_m` (0: none), under `commanded` (may be null: none).
AppliedControls ApplyControls(double file_exposure_s, double file_focus_m,
                              const CameraControls* commanded);

}  // namespace saccade::scene
