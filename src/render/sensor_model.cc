#include "saccade/render/sensor_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <thread>

#include "saccade/core/error.h"

namespace saccade::render {
namespace {

// The most values one sensor holds (two float maps of this size: 2 GiB).
constexpr int64_t kMaxSensorValues = int64_t{1} << 28;
// Frames of at least this many values are exposed in parts on several threads.
constexpr std::size_t kMinSensorPartValues = std::size_t{1} << 18;
// Streams of the counter-based generator: fixed pattern (PRNU, DSNU) and per frame.
constexpr uint64_t kPrnuStream = 0x5052'4e55'0000'0001ULL;
constexpr uint64_t kDsnuStream = 0x4453'4e55'0000'0002ULL;
constexpr uint64_t kFrameStream = 0x4652'414d'0000'0003ULL;

// SplitMix64's finaliser: a bijective 64-bit mix.
uint64_t SensorMix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A uniform in (0, 1) from 32 bits.
double SensorUniform(uint32_t bits) { return (static_cast<double>(bits) + 0.5) * 0x1p-32; }

// The standard normal quantile (Acklam's rational approximation: relative error below
// 1.15e-9 over (0, 1)).
double NormalQuantile(double p) {
  constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                          1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                          6.680131188771972e+01, -1.328068155288572e+01};
  constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                          -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                          3.754408661907416e+00};
  constexpr double kLow = 0.02425;
  const auto tail = [&](double q) {  // q = min(p, 1 - p) < kLow: the lower tail's value
    const double r = std::sqrt(-2.0 * std::log(q));
    return (((((c[0] * r + c[1]) * r + c[2]) * r + c[3]) * r + c[4]) * r + c[5]) /
           ((((d[0] * r + d[1]) * r + d[2]) * r + d[3]) * r + 1.0);
  };
  if (p < kLow) return tail(p);
  if (p > 1.0 - kLow) return -tail(1.0 - p);
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

// The quantile sampled at kGaussianBins + 1 evenly spaced probabilities (the ends unused).
constexpr int kGaussianBinBits = 12;
constexpr int kGaussianBins = 1 << kGaussianBinBits;

const std::vector<double>& GaussianTable() {
  static const std::vector<double> table = [] {
    std::vector<double> t(kGaussianBins + 1, 0.0);
    for (int i = 1; i < kGaussianBins; ++i) {
      t[i] = NormalQuantile(static_cast<double>(i) / kGaussianBins);
    }
    return t;
  }();
  return table;
}

// A standard normal deviate from 32 bits by inversion: the quantile interpolated linearly
// between kGaussianBins evenly spaced probabilities (its variance within 1e-6 of 1: the
// quantile is nearly straight over a bin), exact in the two outer bins (the tails, to
// +-6.3). A table look-up instead of Box-Muller's logarithm and cosine: 5 times as fast.
// `table`: GaussianTable()'s data (looked up once by the caller).
inline double SensorGaussian(const double* table, uint32_t bits) {
  const uint32_t bin = bits >> (32 - kGaussianBinBits);
  if (bin == 0 || bin == kGaussianBins - 1) [[unlikely]] {
    return NormalQuantile(SensorUniform(bits));
  }
  const double* t = table + bin;
  // The low bits as a fraction of the bin: 2^52 + the bits, by their bit pattern, less 2^52 (an
  // integer's conversion to double would wait on the register's previous value).
  const uint64_t low = bits & ((1u << (32 - kGaussianBinBits)) - 1);
  const double frac = (std::bit_cast<double>(0x4330'0000'0000'0000ULL | low) - 0x1p52 + 0.5) *
                      (1.0 / (1u << (32 - kGaussianBinBits)));
  return t[0] + frac * (t[1] - t[0]);
}

// x >= 0 rounded half up, as std::round, to an integer (without a call into libm).
int64_t RoundNonNegative(double x) { return static_cast<int64_t>(x + 0.5); }

// x in [0, 2^51) rounded to the nearest whole number, ties to even (std::round differs only at
// exact ties, which continuous deviates never are), in double arithmetic: without converting to
// an integer and back, whose conversion to double waits on the register's previous value (a
// dependency from one value to the next).
double RoundWhole(double x) {
  constexpr double kShift = 0x1.8p52;  // adding it leaves no fraction bits (IEEE arithmetic:
  return (x + kShift) - kShift;        // without -ffast-math the sum is not folded away)
}

// A Poisson deviate of mean `lambda` from 32 bits: inversion below kExactPoissonMean, the
// Gaussian approximation (rounded to whole electrons) above.
inline double SensorPoisson(const double* table, double lambda, uint32_t bits) {
  if (lambda <= 0.0) return 0.0;
  if (lambda >= kExactPoissonMean) [[likely]] {
    const double e = lambda + std::sqrt(lambda) * SensorGaussian(table, bits);
    return e > 0.0 ? RoundWhole(e) : 0.0;
  }
  const double u = SensorUniform(bits);
  double p = std::exp(-lambda);
  double cdf = p;
  double k = 0.0;
  const double last = lambda + 12.0 * std::sqrt(lambda) + 20.0;  // beyond: below 1e-30
  while (u > cdf && k < last) {
    k += 1.0;
    p *= lambda / k;
    cdf += p;
  }
  return k;
}

// Whether an image of `format` holds a sensor's values of `channels`: kRgb8 for 3; kGray8 or
// an 8-bit Bayer mosaic (one photosite a pixel) for 1.
bool Fits(PixelFormat format, int channels) {
  if (channels == 3) return format == PixelFormat::kRgb8;
  return format == PixelFormat::kGray8 || (IsBayer(format) && BytesPerPixel(format) == 1);
}

// part(first, end) over [0, n): in up to four parts on as many threads (up to the cores), each
// of at least kMinSensorPartValues; in one where that is the whole.
template <typename Part>
void ForParts(std::size_t n, const Part& part) {
  const unsigned threads = std::min<unsigned>(4, std::max(1u, std::thread::hardware_concurrency()));
  if (n < 2 * kMinSensorPartValues || threads < 2) {
    part(std::size_t{0}, n);
    return;
  }
  const std::size_t parts = std::min<std::size_t>(threads, n / kMinSensorPartValues);
  std::vector<std::thread> workers;
  for (std::size_t p = 1; p < parts; ++p) {
    workers.emplace_back(part, n * p / parts, n * (p + 1) / parts);
  }
  part(std::size_t{0}, n / parts);
  for (std::thread& t : workers) t.join();
}

// ForParts over the values of `height` rows of `row_values` each: row(y, x0, x1) for the
// values [x0, x1) of row y that a part holds.
template <typename Row>
void ForRowParts(int height, std::size_t row_values, const Row& row) {
  ForParts(static_cast<std::size_t>(height) * row_values, [&](std::size_t first, std::size_t end) {
    for (std::size_t y = first / row_values; y * row_values < end; ++y) {
      row(static_cast<int>(y), std::max(first, y * row_values) - y * row_values,
          std::min(end, (y + 1) * row_values) - y * row_values);
    }
  });
}

uint64_t HashName(uint64_t seed, const std::string& name) {
  uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (const char c : name) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ULL;
  return SensorMix(seed ^ SensorMix(h));
}

}  // namespace

SensorModel::SensorModel(const scene::EmvaSensor& params, uint64_t seed, const std::string& camera,
                         int width, int height, int channels)
    : params_(params),
      stream_(HashName(seed, camera)),
      width_(width),
      height_(height),
      channels_(channels) {
  params_.Validate();
  if (width <= 0 || height <= 0 || (channels != 1 && channels != 3) ||
      int64_t{width} * height * channels > kMaxSensorValues) {
    throw InvalidArgument(fmt::format(
        "SensorModel: expected a positive size of 1 or 3 channels and at most {} values, got "
        "{} x {} x {}",
        kMaxSensorValues, width, height, channels));
  }
  const std::size_t n = static_cast<std::size_t>(width) * height * channels;
  prnu_.resize(n);
  dsnu_.resize(n);
  const double prnu = params_.prnu_percent / 100.0;
  const uint64_t prnu_key = SensorMix(stream_ ^ kPrnuStream);
  const uint64_t dsnu_key = SensorMix(stream_ ^ kDsnuStream);
  const double* const table = GaussianTable().data();
  for (std::size_t i = 0; i < n; ++i) {
    const auto prnu_bits = static_cast<uint32_t>(SensorMix(prnu_key + i));
    const double gain = 1.0 + prnu * SensorGaussian(table, prnu_bits);
    prnu_[i] = static_cast<float>(std::max(0.0, gain));
    const auto dsnu_bits = static_cast<uint32_t>(SensorMix(dsnu_key + i));
    dsnu_[i] = static_cast<float>(params_.dsnu_e * SensorGaussian(table, dsnu_bits));
  }
}

void SensorModel::Expose(const float* photons, int64_t frame_index, uint16_t* raw,
                         double gain) const {
  const uint64_t key =
      SensorMix(stream_ ^ SensorMix(kFrameStream + static_cast<uint64_t>(frame_index)));
  const double eta = params_.quantum_efficiency;
  const double K = params_.gain_dn_per_e * gain;  // the camera's gain amplifies K
  const double sigma_d = params_.dark_noise_e;
  const double sat = params_.saturation_e;
  const double offset = params_.black_level_dn;
  const double max_dn = params_.MaxDn();
  const double* const table = GaussianTable().data();
  const float* const prnu = prnu_.data();
  const float* const dsnu = dsnu_.data();
  const auto part = [=](std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; ++i) {
      // One 64-bit hash a value: its upper half draws the shot noise, its lower the dark noise.
      const uint64_t h = SensorMix(key + static_cast<uint64_t>(i));
      const double lambda = eta * std::max(0.0f, photons[i]) * prnu[i];
      double e = SensorPoisson(table, lambda, static_cast<uint32_t>(h >> 32));
      e += sigma_d * SensorGaussian(table, static_cast<uint32_t>(h)) + dsnu[i];
      e = std::min(e, sat);  // the full well
      // round() then clamp to [0, max_dn], as one clamp and a rounding of the non-negative.
      raw[i] = static_cast<uint16_t>(RoundNonNegative(std::clamp(K * e + offset, 0.0, max_dn)));
    }
  };
  // Each value depends on its index alone: parts give the same bits as one loop.
  ForParts(values(), part);
}

std::vector<uint16_t> SensorModel::ExposeUniform(double mean_photons, int64_t frame_index) const {
  const std::vector<float> photons(values(), static_cast<float>(mean_photons));
  std::vector<uint16_t> raw(values());
  Expose(photons.data(), frame_index, raw.data());
  return raw;
}

std::vector<uint16_t> SensorModel::ExposeRendered(const ImageView& rendered, double exposure_s,
                                                  int64_t frame_index, Image* image8,
                                                  double gain) const {
  const PixelFormat expected = channels_ == 3 ? PixelFormat::kRgb8 : PixelFormat::kGray8;
  if (rendered.width() != width_ || rendered.height() != height_ ||
      !Fits(rendered.format(), channels_)) {
    throw InvalidArgument(fmt::format(
        "SensorModel::ExposeRendered: expected a {} x {} {} image, got {} x {} {}", width_, height_,
        ToString(expected), rendered.width(), rendered.height(), ToString(rendered.format())));
  }
  const double scale = params_.photons_per_second * exposure_s / 255.0;
  float photons_of[256];  // each 8-bit value's photons, as the product per value gave them
  for (int v = 0; v < 256; ++v) photons_of[v] = static_cast<float>(v * scale);
  std::vector<float> photons(values());
  const std::size_t row_values = static_cast<std::size_t>(width_) * channels_;
  ForRowParts(height_, row_values, [&](int y, std::size_t x0, std::size_t x1) {
    const uint8_t* row = rendered.row(y);
    for (std::size_t x = x0; x < x1; ++x) photons[y * row_values + x] = photons_of[row[x]];
  });
  std::vector<uint16_t> raw(values());
  Expose(photons.data(), frame_index, raw.data(), gain);
  if (image8 != nullptr) To8Bit(raw.data(), image8);
  return raw;
}

void SensorModel::To8Bit(const uint16_t* raw, Image* image8) const {
  const PixelFormat expected = channels_ == 3 ? PixelFormat::kRgb8 : PixelFormat::kGray8;
  if (image8->width() != width_ || image8->height() != height_ ||
      !Fits(image8->format(), channels_)) {
    throw InvalidArgument(fmt::format(
        "SensorModel::To8Bit: expected a {} x {} {} image, got {} x {} {}", width_, height_,
        ToString(expected), image8->width(), image8->height(), ToString(image8->format())));
  }
  const double scale = 255.0 / params_.MaxDn();
  // Each raw value's 8-bit value, as the product per value gave it.
  std::vector<uint8_t> to8(static_cast<std::size_t>(params_.MaxDn()) + 1);
  for (std::size_t v = 0; v < to8.size(); ++v) {
    to8[v] = static_cast<uint8_t>(RoundNonNegative(static_cast<double>(v) * scale));
  }
  const std::size_t row_values = static_cast<std::size_t>(width_) * channels_;
  ForRowParts(height_, row_values, [&](int y, std::size_t x0, std::size_t x1) {
    uint8_t* row = image8->row(y);
    for (std::size_t x = x0; x < x1; ++x) row[x] = to8[raw[y * row_values + x]];
  });
}

}  // namespace saccade::render
