#include "saccade/render/sensor_model.h"

#include <fmt/format.h>

#include <algorithm>
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

// A standard normal deviate from 64 bits (Box-Muller, the cosine half).
double SensorGaussian(uint64_t bits) {
  const double u1 = SensorUniform(static_cast<uint32_t>(bits >> 32));
  const double u2 = SensorUniform(static_cast<uint32_t>(bits));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// A Poisson deviate of mean `lambda` from 64 bits: inversion below kExactPoissonMean, the
// Gaussian approximation (rounded to whole electrons) above.
double SensorPoisson(double lambda, uint64_t bits) {
  if (lambda <= 0.0) return 0.0;
  if (lambda >= kExactPoissonMean) {
    return std::max(0.0, std::round(lambda + std::sqrt(lambda) * SensorGaussian(bits)));
  }
  const double u = (static_cast<double>(bits >> 11) + 0.5) * 0x1p-53;
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
  for (std::size_t i = 0; i < n; ++i) {
    const double gain = 1.0 + prnu * SensorGaussian(SensorMix(prnu_key + i));
    prnu_[i] = static_cast<float>(std::max(0.0, gain));
    dsnu_[i] = static_cast<float>(params_.dsnu_e * SensorGaussian(SensorMix(dsnu_key + i)));
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
  const auto part = [&](std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; ++i) {
      const uint64_t h = key + 2 * static_cast<uint64_t>(i);
      const double lambda = eta * std::max(0.0f, photons[i]) * prnu_[i];
      double e = SensorPoisson(lambda, SensorMix(h));
      e += sigma_d * SensorGaussian(SensorMix(h + 1)) + dsnu_[i];
      e = std::min(e, sat);  // the full well
      raw[i] = static_cast<uint16_t>(std::clamp(std::round(K * e + offset), 0.0, max_dn));
    }
  };
  const std::size_t n = values();
  // Each value depends on its index alone: parts give the same bits as one loop.
  const unsigned threads = std::min<unsigned>(4, std::max(1u, std::thread::hardware_concurrency()));
  if (n < 2 * kMinSensorPartValues || threads < 2) {
    part(0, n);
    return;
  }
  const std::size_t parts = std::min<std::size_t>(threads, n / kMinSensorPartValues);
  std::vector<std::thread> workers;
  for (std::size_t p = 1; p < parts; ++p) {
    workers.emplace_back(part, n * p / parts, n * (p + 1) / parts);
  }
  part(0, n / parts);
  for (std::thread& t : workers) t.join();
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
  std::vector<float> photons(values());
  const std::size_t row_values = static_cast<std::size_t>(width_) * channels_;
  for (int y = 0; y < height_; ++y) {
    const uint8_t* row = rendered.row(y);
    for (std::size_t x = 0; x < row_values; ++x) {
      photons[y * row_values + x] = static_cast<float>(row[x] * scale);
    }
  }
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
  const std::size_t row_values = static_cast<std::size_t>(width_) * channels_;
  for (int y = 0; y < height_; ++y) {
    uint8_t* row = image8->row(y);
    for (std::size_t x = 0; x < row_values; ++x) {
      row[x] = static_cast<uint8_t>(std::lround(raw[y * row_values + x] * scale));
    }
  }
}

}  // namespace saccade::render
