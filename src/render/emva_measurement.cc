#include "saccade/render/emva_measurement.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "saccade/core/error.h"

namespace saccade::render {
namespace {

// Quantisation noise of a DN, DN^2 (EMVA 1288 4.0 eq. 6).
constexpr double kQuantisationVariance = 1.0 / 12.0;

void CheckSameSize(const Plane& a, const Plane& b, const char* function) {
  if (a.values.empty() || a.width != b.width || a.height != b.height ||
      a.values.size() != b.values.size()) {
    throw InvalidArgument(
        fmt::format("{}: expected frames of one non-empty size, got {} x {} and {} x {}", function,
                    a.width, a.height, b.width, b.height));
  }
}

// Least squares y = slope x + intercept.
std::pair<double, double> FitLine(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0.0;
  double sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  const double slope = sxx > 0.0 ? sxy / sxx : 0.0;
  return {slope, my - slope * mx};
}

// Points (sorted by exposure) over which the variance is averaged to find its maximum.
constexpr int kSaturationWindow = 5;

// The figures of the photon transfer curve (K, sigma_d, mu_e.sat, eta) into `r`.
void EvaluateTransfer(EmvaResult& r) {
  const std::vector<EmvaPoint>& p = r.points;
  // The largest variance of the series smoothed over kSaturationWindow neighbours (by
  // exposure): near its maximum the curve is flat to within the variances' sampling error (1 %
  // at 128 x 128 pixels), so one point's maximum wanders by a percent of mu_e.sat.
  const int n = static_cast<int>(p.size());
  const auto smoothed = [&](int i) {
    const int first = std::max(0, i - kSaturationWindow / 2);
    const int end = std::min(n, i + kSaturationWindow / 2 + 1);
    double sum = 0.0;
    for (int k = first; k < end; ++k) sum += p[k].bright.variance;
    return sum / (end - first);
  };
  int sat = 0;
  double sat_variance = smoothed(0);
  for (int i = 1; i < n; ++i) {
    const double v = smoothed(i);
    if (v > sat_variance) {
      sat = i;
      sat_variance = v;
    }
  }
  if (sat == static_cast<int>(p.size()) - 1) {
    throw InvalidArgument(fmt::format(
        "EvaluateEmva: the variance is largest at the last point ({} s, {:.1f} DN): the series "
        "does not reach saturation; add longer exposures",
        p[sat].exposure_s, p[sat].bright.mean));
  }
  r.saturation_index = sat;
  const double sat_signal = p[sat].bright.mean - p[sat].dark.mean;
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> photons;
  std::vector<double> signal;
  for (int i = 0; i < sat; ++i) {
    const double net = p[i].bright.mean - p[i].dark.mean;
    if (!(net > 0.0 && net <= kEmvaFitFraction * sat_signal)) continue;
    x.push_back(net);
    y.push_back(p[i].bright.variance - p[i].dark.variance);
    if (std::isfinite(p[i].photons)) {
      photons.push_back(p[i].photons);
      signal.push_back(net);
    }
  }
  if (static_cast<int>(x.size()) < kMinEmvaFitPoints) {
    throw InvalidArgument(fmt::format(
        "EvaluateEmva: {} point(s) between dark and 70 % of saturation ({:.1f} DN above dark); "
        "the photon transfer fit needs at least {}: add exposures below saturation",
        x.size(), sat_signal, kMinEmvaFitPoints));
  }
  r.fit_points = static_cast<int>(x.size());
  std::tie(r.gain_dn_per_e, r.gain_intercept) = FitLine(x, y);
  if (!(r.gain_dn_per_e > 0.0)) {
    throw InvalidArgument(fmt::format(
        "EvaluateEmva: the photon transfer curve does not rise (slope K = {}): are the flat "
        "fields brighter than the dark ones, and the pairs two different frames?",
        r.gain_dn_per_e));
  }
  const double K = r.gain_dn_per_e;
  r.mu_y_dark = p.front().dark.mean;
  r.sigma_y_dark = std::sqrt(p.front().dark.variance);
  r.dark_noise_e = std::sqrt(std::max(0.0, p.front().dark.variance - kQuantisationVariance)) / K;
  r.saturation_e = sat_signal / K;
  r.full_well_e = (p.back().bright.mean - p.back().dark.mean) / K;
  if (photons.size() == x.size()) {  // responsivity R through the origin, eta = R / K
    double sxy = 0.0;
    double sxx = 0.0;
    for (std::size_t i = 0; i < photons.size(); ++i) {
      sxy += photons[i] * signal[i];
      sxx += photons[i] * photons[i];
    }
    if (sxx > 0.0) r.quantum_efficiency = sxy / sxx / K;
  }
  r.snr_max_db = 20.0 * std::log10(std::sqrt(r.saturation_e));
  r.dynamic_range_db =
      r.dark_noise_e > 0.0 ? 20.0 * std::log10(r.saturation_e / r.dark_noise_e) : 0.0;
}

// Takes the frames of MeasureSensor, each with a frame index of its own.
class SeriesTaker {
 public:
  SeriesTaker(const SensorModel& sensor, const EmvaFrameSink& sink)
      : sensor_(sensor), sink_(sink) {}

  std::vector<uint16_t> Take(const char* kind, double exposure_s, int index) {
    const double photons = kind[0] == 'd' ? 0.0 : sensor_.params().photons_per_second * exposure_s;
    std::vector<uint16_t> raw = sensor_.ExposeUniform(photons, frame_++);
    if (sink_) sink_(kind, exposure_s, index, raw);
    return raw;
  }
  Plane TakePlane(const char* kind, double exposure_s, int index) {
    return PlaneFromRaw(Take(kind, exposure_s, index), sensor_.width(), sensor_.height());
  }
  EmvaPoint Point(double exposure_s) {
    EmvaPoint p;
    p.exposure_s = exposure_s;
    p.photons = sensor_.params().photons_per_second * exposure_s;
    p.dark = MeasurePair(TakePlane("dark", exposure_s, 0), TakePlane("dark", exposure_s, 1));
    p.bright = MeasurePair(TakePlane("flat", exposure_s, 0), TakePlane("flat", exposure_s, 1));
    return p;
  }
  StackStats Stack(const char* kind, double exposure_s, int frames) {
    std::vector<Plane> planes;
    for (int i = 0; i < frames; ++i) planes.push_back(TakePlane(kind, exposure_s, i));
    return MeasureStack(planes);
  }

 private:
  const SensorModel& sensor_;
  const EmvaFrameSink& sink_;
  int64_t frame_ = 0;
};

}  // namespace

Plane PlaneFromRaw(const std::vector<uint16_t>& raw, int width, int height) {
  Plane plane{width, height, std::vector<double>(raw.begin(), raw.end())};
  if (plane.values.size() != static_cast<std::size_t>(width) * height) {
    throw InvalidArgument(
        fmt::format("PlaneFromRaw: {} values for {} x {} pixels", raw.size(), width, height));
  }
  return plane;
}

Plane PlaneFromImage(const Image& image, int channel) {
  int channels = 0;
  switch (image.format()) {
    case PixelFormat::kGray8:
    case PixelFormat::kGray16:
      channels = 1;
      break;
    case PixelFormat::kRgb8:
      channels = 3;
      break;
    case PixelFormat::kRgba8:
      channels = 4;
      break;
    default:
      throw InvalidArgument(fmt::format(
          "PlaneFromImage: expected an 8- or 16-bit gray or an 8-bit colour image, got {}",
          ToString(image.format())));
  }
  if (channel < 0 || channel >= channels) {
    throw InvalidArgument(fmt::format("PlaneFromImage: channel {} of a {} image of {} channel(s)",
                                      channel, ToString(image.format()), channels));
  }
  Plane plane{image.width(), image.height(), {}};
  plane.values.reserve(static_cast<std::size_t>(image.width()) * image.height());
  for (int y = 0; y < image.height(); ++y) {
    const uint8_t* row = image.row(y);
    for (int x = 0; x < image.width(); ++x) {
      if (image.format() == PixelFormat::kGray16) {
        uint16_t v = 0;
        std::memcpy(&v, row + 2 * x, 2);
        plane.values.push_back(v);
      } else {
        plane.values.push_back(row[x * channels + channel]);
      }
    }
  }
  return plane;
}

PairStats MeasurePair(const Plane& a, const Plane& b) {
  CheckSameSize(a, b, "MeasurePair");
  const double n = static_cast<double>(a.values.size());
  double sum = 0.0;
  double diff_sum = 0.0;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    sum += a.values[i] + b.values[i];
    diff_sum += a.values[i] - b.values[i];
  }
  const double diff_mean = diff_sum / n;
  double diff_var = 0.0;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    const double d = a.values[i] - b.values[i] - diff_mean;
    diff_var += d * d;
  }
  return {sum / (2.0 * n), diff_var / (n - 1.0) / 2.0};
}

StackStats MeasureStack(const std::vector<Plane>& frames) {
  if (frames.size() < 2) {
    throw InvalidArgument(
        fmt::format("MeasureStack: expected at least 2 frames, got {}", frames.size()));
  }
  for (const Plane& f : frames) CheckSameSize(frames.front(), f, "MeasureStack");
  const std::size_t n = frames.front().values.size();
  const double L = static_cast<double>(frames.size());
  std::vector<double> average(n, 0.0);
  double temporal = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0.0;
    for (const Plane& f : frames) sum += f.values[i];
    average[i] = sum / L;
    double var = 0.0;
    for (const Plane& f : frames) var += (f.values[i] - average[i]) * (f.values[i] - average[i]);
    temporal += var / (L - 1.0);
  }
  StackStats s;
  s.frames = static_cast<int>(frames.size());
  s.mean = std::accumulate(average.begin(), average.end(), 0.0) / static_cast<double>(n);
  double spatial = 0.0;
  for (const double v : average) spatial += (v - s.mean) * (v - s.mean);
  s.temporal_variance = temporal / static_cast<double>(n);
  // EMVA 1288 4.0 eq. 34: the average of L frames keeps sigma^2 / L of the temporal noise.
  s.spatial_variance = spatial / (static_cast<double>(n) - 1.0) - s.temporal_variance / L;
  return s;
}

EmvaResult EvaluateEmva(std::vector<EmvaPoint> points, const StackStats& dark_stack,
                        const StackStats& bright_stack) {
  if (static_cast<int>(points.size()) < kMinEmvaPoints) {
    throw InvalidArgument(fmt::format(
        "EvaluateEmva: {} exposure(s); the series needs at least {}, from dark to beyond "
        "saturation",
        points.size(), kMinEmvaPoints));
  }
  std::stable_sort(points.begin(), points.end(), [](const EmvaPoint& a, const EmvaPoint& b) {
    return a.exposure_s < b.exposure_s;
  });
  EmvaResult r;
  r.points = std::move(points);
  EvaluateTransfer(r);
  if (!(bright_stack.mean > dark_stack.mean) || dark_stack.frames < 2 || bright_stack.frames < 2) {
    throw InvalidArgument(fmt::format(
        "EvaluateEmva: the nonuniformity stacks need 2 frames or more each and a bright stack "
        "above the dark one, got {} dark frame(s) at {:.2f} DN and {} bright at {:.2f} DN",
        dark_stack.frames, dark_stack.mean, bright_stack.frames, bright_stack.mean));
  }
  r.dark_stack = dark_stack;
  r.bright_stack = bright_stack;
  r.dsnu_dn = std::sqrt(std::max(0.0, dark_stack.spatial_variance));
  r.dsnu_e = r.dsnu_dn / r.gain_dn_per_e;
  r.prnu_percent =
      100.0 *
      std::sqrt(std::max(0.0, bright_stack.spatial_variance - dark_stack.spatial_variance)) /
      (bright_stack.mean - dark_stack.mean);
  return r;
}

std::string EmvaResult::CurveTable() const {
  std::string out = fmt::format("{:>14} {:>12} {:>11} {:>12} {:>11} {:>12}\n", "exposure_us",
                                "photons", "mu_y.dark", "sigma2_y.dark", "mu_y", "sigma2_y");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const EmvaPoint& p = points[i];
    out += fmt::format("{:>14.3f} {:>12.1f} {:>11.3f} {:>12.4f} {:>11.3f} {:>12.4f}{}\n",
                       p.exposure_s * 1e6, p.photons, p.dark.mean, p.dark.variance, p.bright.mean,
                       p.bright.variance,
                       static_cast<int>(i) == saturation_index ? "  <- saturation" : "");
  }
  return out;
}

std::string EmvaResult::BriefReport() const {
  std::string out;
  out += fmt::format("system gain K            {:.5f} DN/e- ({:.3f} e-/DN), {} fit points\n",
                     gain_dn_per_e, 1.0 / gain_dn_per_e, fit_points);
  out +=
      fmt::format("temporal dark noise      {:.3f} e- ({:.3f} DN)\n", dark_noise_e, sigma_y_dark);
  out +=
      fmt::format("saturation capacity      {:.1f} e- (at the largest variance)\n", saturation_e);
  out += fmt::format("full well (plateau)      {:.1f} e-\n", full_well_e);
  out += fmt::format("quantum efficiency       {}\n",
                     std::isfinite(quantum_efficiency) ? fmt::format("{:.4f}", quantum_efficiency)
                                                       : std::string("- (no photon counts)"));
  out += fmt::format("DSNU1288                 {:.3f} e- ({:.3f} DN), L = {}\n", dsnu_e, dsnu_dn,
                     dark_stack.frames);
  out +=
      fmt::format("PRNU1288                 {:.3f} %, L = {}\n", prnu_percent, bright_stack.frames);
  out += fmt::format("dark level               {:.3f} DN\n", mu_y_dark);
  out += fmt::format("SNR max                  {:.2f} dB\n", snr_max_db);
  out += fmt::format("dynamic range            {:.2f} dB (mu_e.sat / sigma_d)\n", dynamic_range_db);
  return out;
}

std::string EmvaSeriesOptions::Check() const {
  if (points < kMinEmvaPoints || points > 1000) {
    return fmt::format("points must be in [{}, 1000], got {}", kMinEmvaPoints, points);
  }
  if (refine_points < 0 || refine_points > 1000) {
    return fmt::format("refine_points must be in [0, 1000], got {}", refine_points);
  }
  if (stack_frames < 2 || stack_frames > 1000) {
    return fmt::format("stack_frames must be in [2, 1000], got {}", stack_frames);
  }
  if (!(beyond_saturation >= 1.05 && beyond_saturation <= 10.0)) {
    return fmt::format("beyond_saturation must be in [1.05, 10], got {}", beyond_saturation);
  }
  return "";
}

}  // namespace saccade::render

namespace saccade::render {

EmvaResult MeasureSensor(const SensorModel& sensor, const EmvaSeriesOptions& options,
                         const EmvaFrameSink& sink) {
  if (const std::string error = options.Check(); !error.empty()) {
    throw InvalidArgument("MeasureSensor: " + error);
  }
  if (sensor.channels() != 1) {
    throw InvalidArgument(fmt::format("MeasureSensor: expected a 1-channel sensor, got {} channels",
                                      sensor.channels()));
  }
  const scene::EmvaSensor& params = sensor.params();
  // The exposure that fills the full well on average.
  const double t_sat =
      params.saturation_e / (params.quantum_efficiency * params.photons_per_second);
  const double t_last = options.beyond_saturation * t_sat;
  SeriesTaker taker(sensor, sink);
  std::vector<EmvaPoint> points;
  for (int k = 0; k < options.points; ++k) {
    points.push_back(taker.Point(t_last * k / (options.points - 1)));
  }
  // Denser around the coarse maximum of the variance: mu_e.sat is read there.
  int m = 0;
  for (int k = 1; k < options.points; ++k) {
    if (points[k].bright.variance > points[m].bright.variance) m = k;
  }
  const double from = points[std::max(m - 1, 0)].exposure_s;
  const double to = points[std::min(m + 1, options.points - 1)].exposure_s;
  for (int k = 1; k <= options.refine_points; ++k) {
    points.push_back(taker.Point(from + (to - from) * k / (options.refine_points + 1)));
  }
  const double t_half = 0.5 * t_sat;
  const StackStats dark = taker.Stack("dark", t_half, options.stack_frames);
  const StackStats bright = taker.Stack("flat", t_half, options.stack_frames);
  return EvaluateEmva(std::move(points), dark, bright);
}

}  // namespace saccade::render
