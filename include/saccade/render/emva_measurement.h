#pragma once
// EMVA 1288 (release 4.0, linear model) measurement: the photon transfer method on dark and
// flat-field pairs over a series of exposures, and the spatial nonuniformity from stacks of
// frames. It measures what render/sensor_model.h simulates, and real cameras' files alike
// (`saccade emva`, docs/sensor.md).
//
// Per exposure, frames A and B (EMVA 1288 4.0 section 4):
//   mu_y        = (mean(A) + mean(B)) / 2
//   sigma_y^2   = var(A - B) / 2                  (temporal noise; the fixed pattern cancels)
// Photon transfer: sigma_y^2 - sigma_y.dark^2 = K (mu_y - mu_y.dark), fitted (least squares,
// with an intercept) over the points with 0 < mu_y - mu_y.dark <= 70 % of the saturation's;
// saturation at the largest sigma_y^2 (averaged over 5 neighbouring exposures): mu_e.sat = (mu_y.sat - mu_y.dark) / K (below the full
// well: pixels reach it one by one, so the variance peaks before the mean gets there);
// dark noise sigma_d = sqrt(sigma_y.dark^2 - 1/12) / K (1/12 DN^2: quantisation), from the
// dark pair of the shortest exposure; eta = R / K with R the slope of mu_y - mu_y.dark against
// the photons mu_p, when they are known.
// Nonuniformity from L frames (4.0 section 8): the spatial variance of their average, less the
// temporal variance left in it: s_y^2 = s^2(<y>) - sigma_stack^2 / L; DSNU1288 = s_y.dark / K
// (electrons), PRNU1288 = sqrt(s_y.50^2 - s_y.dark^2) / (mu_y.50 - mu_y.dark) (percent).

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/render/sensor_model.h"

namespace saccade::render {

/// One frame's values (one channel), row-major.
struct Plane {
  int width = 0;
  int height = 0;
  std::vector<double> values;
};

/// A raw frame of a 1-channel sensor as a plane.
Plane PlaneFromRaw(const std::vector<uint16_t>& raw, int width, int height);
/// One channel of an image (kGray8, kGray16, kRgb8, kRgba8; `channel` < its channels).
/// Throws InvalidArgument on another format or channel.
Plane PlaneFromImage(const Image& image, int channel);

/// Mean and temporal variance of a pair of frames.
struct PairStats {
  double mean = 0.0;      ///< mu_y, DN
  double variance = 0.0;  ///< sigma_y^2 = var(A - B) / 2, DN^2
};
/// Throws InvalidArgument when the sizes differ or a frame is empty.
PairStats MeasurePair(const Plane& a, const Plane& b);

/// A stack of L frames of one exposure.
struct StackStats {
  int frames = 0;                  ///< L
  double mean = 0.0;               ///< DN
  double spatial_variance = 0.0;   ///< s_y^2, the temporal residue removed, DN^2
  double temporal_variance = 0.0;  ///< sigma_y^2 per pixel across the stack, DN^2
};
/// Throws InvalidArgument when fewer than 2 frames or their sizes differ.
StackStats MeasureStack(const std::vector<Plane>& frames);

/// One point of the photon transfer curve.
struct EmvaPoint {
  double exposure_s = 0.0;
  /// Mean photons a pixel collects (mu_p); NaN when not known (then no eta is measured).
  double photons = std::numeric_limits<double>::quiet_NaN();
  PairStats dark;
  PairStats bright;
};

/// What the evaluation found.
struct EmvaResult {
  std::vector<EmvaPoint> points;  ///< by exposure
  int saturation_index = -1;      ///< the point of the largest bright variance
  int fit_points = 0;             ///< points in the photon transfer fit
  double gain_dn_per_e = 0.0;     ///< K
  double gain_intercept = 0.0;    ///< the fit's intercept, DN^2
  double dark_noise_e = 0.0;      ///< sigma_d
  /// mu_e.sat as EMVA 1288 defines it: at the variance's maximum, which lies below the full
  /// well by some 2 to 3 standard deviations of the signal there (shot noise and PRNU).
  double saturation_e = 0.0;
  /// The saturated plateau (mean of the last point less its dark) / K: the full well, or the
  /// ADC's range where that ends first. Not an EMVA 1288 figure.
  double full_well_e = 0.0;
  double dsnu_e = 0.0;                                                   ///< DSNU1288, electrons
  double dsnu_dn = 0.0;                                                  ///< DSNU1288, DN
  double prnu_percent = 0.0;                                             ///< PRNU1288
  double quantum_efficiency = std::numeric_limits<double>::quiet_NaN();  ///< NaN: no photons
  double mu_y_dark = 0.0;                                                ///< DN, shortest exposure
  double sigma_y_dark = 0.0;                                             ///< DN, shortest exposure
  double snr_max_db = 0.0;        ///< 20 log10 sqrt(mu_e.sat)
  double dynamic_range_db = 0.0;  ///< 20 log10 (mu_e.sat / sigma_d)
  StackStats dark_stack;
  StackStats bright_stack;

  /// The photon transfer curve as a text table, one line a point.
  std::string CurveTable() const;
  /// The figures, one a line.
  std::string BriefReport() const;
};

/// Fit share of the saturation signal (EMVA 1288 4.0: 70 %).
inline constexpr double kEmvaFitFraction = 0.7;
/// The fewest points of a series, and of its fit.
inline constexpr int kMinEmvaPoints = 5;
inline constexpr int kMinEmvaFitPoints = 3;

/// The figures from a series and the two stacks (dark and bright at about 50 % saturation, of
/// the same exposure). Throws InvalidArgument naming what is missing: too few points, too few
/// in the linear range, no saturation (the largest variance at the last point), a bright stack
/// no brighter than the dark one.
EmvaResult EvaluateEmva(std::vector<EmvaPoint> points, const StackStats& dark_stack,
                        const StackStats& bright_stack);

/// How `MeasureSensor` takes its series.
struct EmvaSeriesOptions {
  int points = 40;                 ///< exposures of the even series, dark to beyond saturation
  int refine_points = 16;          ///< more around the coarse maximum of the variance
  int stack_frames = 16;           ///< L of the nonuniformity stacks
  double beyond_saturation = 1.3;  ///< the last exposure, as a multiple of saturation's
  /// Returns an empty string when valid, else what is wrong.
  std::string Check() const;
};

/// Called with every frame taken: "dark" or "flat", the exposure, the frame's index at that
/// exposure (0, 1: the pair; more: the stack) and its raw values.
using EmvaFrameSink = std::function<void(const std::string& kind, double exposure_s, int index,
                                         const std::vector<uint16_t>& raw)>;

/// The whole EMVA 1288 series through a 1-channel `sensor`, uniformly lit (full-white
/// rendered value: photons_per_second x exposure photons a pixel): dark and flat pairs at
/// options.points exposures from 0 to beyond saturation, refined around the variance's
/// maximum, and the stacks at the exposure nearest 50 % saturation. Deterministic.
EmvaResult MeasureSensor(const SensorModel& sensor, const EmvaSeriesOptions& options,
                         const EmvaFrameSink& sink = {});

}  // namespace saccade::render
