#pragma once
// A camera's sensor as EMVA 1288 (release 4.0, linear model) states it: the figures of a
// camera's EMVA 1288 data sheet, so that a scene can name a real camera's values.
//
// The model (render/sensor_model.h simulates it, render/emva_measurement.h measures it):
//   mu_p      mean photons a pixel collects in the exposure
//   electrons = Poisson(eta * mu_p * (1 + PRNU_i)) + N(0, dark_noise_e^2) + DSNU_i,
//               clipped to [.., saturation_e]   (PRNU_i, DSNU_i: fixed per pixel)
//   y [DN]    = round(K * electrons + black_level_dn), clipped to [0, 2^bit_depth - 1]
// so that mu_y - mu_y.dark = K * eta * mu_p and sigma_y^2 = K^2 (sigma_d^2 + sigma_e^2) +
// 1/12 DN^2 (EMVA 1288 4.0 eqs. 4-7; 1/12: the quantisation noise).

#include <optional>
#include <string>
#include <vector>

namespace saccade::scene {

struct EmvaSensor {
  /// Quantum efficiency eta, electrons per photon, in (0, 1].
  double quantum_efficiency = 0.7;
  /// Overall system gain K, DN per electron, in (0, 64].
  double gain_dn_per_e = 0.25;
  /// Temporal dark noise sigma_d, electrons (rms), in [0, 1000].
  double dark_noise_e = 2.5;
  /// Saturation capacity mu_e.sat (full well as the camera uses it), electrons, in (0, 1e7],
  /// and at least kMinDynamicRange times the dark noise.
  double saturation_e = 10000.0;
  /// Dark signal non-uniformity DSNU1288: the standard deviation over pixels of the dark
  /// signal, electrons, >= 0 (at most saturation_e / 10). Fixed per camera.
  double dsnu_e = 0.0;
  /// Photo response non-uniformity PRNU1288: the standard deviation over pixels of the
  /// response, percent of the signal, in [0, 20]. Fixed per camera.
  double prnu_percent = 0.0;
  /// Bits of the raw DN, 8 .. 16.
  int bit_depth = 12;
  /// Offset (black level) of the raw DN, so that dark noise is not clipped at 0; in
  /// [0, 2^bit_depth - 1).
  double black_level_dn = 0.0;
  /// Photons a pixel collects per second of exposure from a full-white rendered pixel (255):
  /// the scale from the rendered value (the radiance proxy) to irradiance. > 0, at most 1e12.
  double photons_per_second = 1e6;
  /// The preset it started from ("" if none): informative.
  std::string preset;

  /// The largest raw DN, 2^bit_depth - 1.
  double MaxDn() const;
  /// Throws InvalidArgument naming the field, the value and the range when one is out of
  /// range, or when the saturation is within the dark noise.
  void Validate() const;
};

/// Saturation at least this many times the dark noise (a dynamic range of 20 dB).
inline constexpr double kMinDynamicRange = 10.0;

/// A named preset of data-sheet figures (see docs/sensor.md for their sources), or nullopt.
std::optional<EmvaSensor> FindEmvaPreset(const std::string& name);
/// Every preset's name, in a fixed order.
std::vector<std::string> EmvaPresetNames();

/// The legacy noise keys (SensorSpec::read_noise_dn, gain_dn_per_e) as an EMVA 1288 sensor:
/// eta 1, K = gain, sigma_d = read noise / K, 8 bits, no offset, no DSNU/PRNU, full well at
/// 255 DN, and photons_per_second such that the mean DN is the rendered value at `exposure_s`.
/// The renderer keeps drawing those keys through their own fast path (the same bits as
/// before); this is their description in the EMVA terms, for `saccade emva`. Throws
/// InvalidArgument when gain_dn_per_e is 0 (no shot noise has no EMVA form) or exposure_s <= 0.
EmvaSensor EmvaFromLegacyNoise(double read_noise_dn, double gain_dn_per_e, double exposure_s);

}  // namespace saccade::scene
