#pragma once
// The EMVA 1288 sensor (scene/emva_sensor.h) as a simulation: mean photons in, raw DN out.
// No GL: it runs on the CPU, after readback, on every device (docs/sensor.md).
//
// Per pixel and channel i (EMVA 1288 4.0, section 2, the linear model):
//   e_i = Poisson(eta * mu_p,i * (1 + PRNU_i)) + N(0, sigma_d^2) + DSNU_i, clipped at mu_e.sat
//   y_i = round(K * e_i + black_level), clipped to [0, 2^bits - 1]
// The Poisson deviate is exact (inversion) below kExactPoissonMean electrons and its Gaussian
// approximation (mean and variance lambda, rounded to whole electrons) above, where the two
// differ by less than 1 % in variance. PRNU_i ~ N(0, prnu^2) and DSNU_i ~ N(0, dsnu^2) are drawn
// once per camera from (seed, camera name); the temporal noise of a frame from (seed, camera
// name, frame index), with a counter-based hash per pixel: the same inputs give the same bits,
// whatever the thread count.

#include <cstdint>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/scene/emva_sensor.h"

namespace saccade::render {

/// Mean electrons above which the shot noise is drawn from its Gaussian approximation.
inline constexpr double kExactPoissonMean = 64.0;

class SensorModel {
 public:
  /// A sensor of `width` x `height` pixels of `channels` (1 or 3) values each, its fixed
  /// pattern drawn from (seed, camera). Validates `params` (throws InvalidArgument) and the
  /// size (positive, at most 2^28 values).
  SensorModel(const scene::EmvaSensor& params, uint64_t seed, const std::string& camera, int width,
              int height, int channels);

  const scene::EmvaSensor& params() const { return params_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  std::size_t values() const { return prnu_.size(); }

  /// One frame: `photons` holds values() mean photon counts (row-major, channels interleaved),
  /// `raw` receives values() DN. Does not throw; deterministic in (seed, camera, frame_index).
  /// `gain`: the camera's analogue gain as a factor (>= 1), which multiplies K (the noise in
  /// electrons stays, the DN per electron grow); 1: the data sheet's K, the same bits as ever.
  void Expose(const float* photons, int64_t frame_index, uint16_t* raw, double gain = 1.0) const;

  /// A uniform exposure of `mean_photons` a pixel (a flat field; 0: a dark field).
  std::vector<uint16_t> ExposeUniform(double mean_photons, int64_t frame_index) const;

  /// A rendered kRgb8 image (channels() 3; with 1 channel a kGray8 image or an 8-bit Bayer
  /// mosaic, a photosite a pixel), its values the radiance proxy: mu_p = value / 255 *
  /// photons_per_second * exposure_s. Returns the raw DN (values()), and, when `image8` is not
  /// null, writes the raw DN scaled to 8 bits (round(y * 255 / (2^bits - 1))) into it
  /// (`image8` may be `rendered`). `gain` as for Expose (a commanded gain, 10^(dB / 20)).
  /// Throws InvalidArgument on a size or format mismatch.
  std::vector<uint16_t> ExposeRendered(const ImageView& rendered, double exposure_s,
                                       int64_t frame_index, Image* image8, double gain = 1.0) const;

  /// ExposeRendered's 8-bit image alone, into `image8` (not null; it may be `rendered`): the
  /// same values, without a frame of raw DN (the renderer's cameras keep only the image).
  void ExposeRendered8(const ImageView& rendered, double exposure_s, int64_t frame_index,
                       Image* image8, double gain = 1.0) const;

  /// Raw DN to 8 bits in place of an image of the sensor's size (kRgb8 for 3 channels, kGray8
  /// or an 8-bit Bayer mosaic for 1): round(y * 255 / (2^bits - 1)).
  void To8Bit(const uint16_t* raw, Image* image8) const;

 private:
  // ExposeRendered's pass; `raw` null: each run's DN in a buffer of the thread's.
  void ExposeRenderedInto(const ImageView& rendered, double exposure_s, int64_t frame_index,
                          uint16_t* raw, Image* image8, double gain) const;

  scene::EmvaSensor params_;
  uint64_t stream_;  // hash of seed and camera name
  int width_;
  int height_;
  int channels_;
  std::vector<float> prnu_;  // 1 + PRNU_i
  std::vector<float> dsnu_;  // DSNU_i, electrons
  int lanes_ = 8;  // the widest vector kernel to use: 8 (AVX-512), 4 (AVX2), 1 (portable: tests)

  friend void UseSensorLanes(SensorModel& sensor, int max_lanes);
};

}  // namespace saccade::render
