// The EMVA 1288 sensor (render/sensor_model.h) and its measurement (render/emva_measurement.h):
// the measurement recovers the configured K, sigma_d, mu_e.sat, DSNU and PRNU (issue 45); the
// sensor is deterministic bit for bit, clips at the full well and follows Poisson statistics.
#include "saccade/render/sensor_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "render/internal_sensor_model.h"
#include "saccade/core/error.h"
#include "saccade/render/emva_measurement.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

// Issue 45: the measured figures within 5 % of the configured ones.
constexpr double kFigureTolerance = 0.05;
// The saturated plateau is the full well in DN exactly; divided by the measured K it carries
// K's error (about 1 % at 128 x 128 pixels).
constexpr double kFullWellTolerance = 0.02;
// Sample statistics of 64 x 64 values: a variance's relative standard error is sqrt(2 / N)
// (2.2 %); 4 standard errors.
constexpr double kVarianceTolerance = 0.09;

scene::EmvaSensor Sensor(double K, double sigma_d, double sat, double dsnu, double prnu, int bits,
                         double black) {
  scene::EmvaSensor s;
  s.quantum_efficiency = 0.6;
  s.gain_dn_per_e = K;
  s.dark_noise_e = sigma_d;
  s.saturation_e = sat;
  s.dsnu_e = dsnu;
  s.prnu_percent = prnu;
  s.bit_depth = bits;
  s.black_level_dn = black;
  s.photons_per_second = 1e6;
  return s;
}

void ExpectRelative(double measured, double configured, const char* what) {
  EXPECT_NEAR(measured / configured, 1.0, kFigureTolerance)
      << what << ": measured " << measured << ", configured " << configured;
}

EmvaResult Measure(const scene::EmvaSensor& s) {
  const SensorModel sensor(s, 7, "emva", 128, 128, 1);
  return MeasureSensor(sensor, EmvaSeriesOptions{});
}

void ExpectRecovers(const scene::EmvaSensor& s) {
  const EmvaResult r = Measure(s);
  ExpectRelative(r.gain_dn_per_e, s.gain_dn_per_e, "K");
  ExpectRelative(r.dark_noise_e, s.dark_noise_e, "sigma_d");
  ExpectRelative(r.saturation_e, s.saturation_e, "mu_e.sat");
  EXPECT_NEAR(r.full_well_e / s.saturation_e, 1.0, kFullWellTolerance) << r.full_well_e;
  // EMVA's mu_e.sat is read where the variance peaks: below the full well, never above.
  EXPECT_LT(r.saturation_e, r.full_well_e);
  ExpectRelative(r.dsnu_e, s.dsnu_e, "DSNU");
  ExpectRelative(r.prnu_percent, s.prnu_percent, "PRNU");
  ExpectRelative(r.quantum_efficiency, s.quantum_efficiency, "eta");
  ::testing::Test::RecordProperty("K", std::to_string(r.gain_dn_per_e));
}

TEST(EmvaMeasurementTest, RecoversAnImx264LikeSensor) {
  ExpectRecovers(Sensor(0.36, 2.3, 10500.0, 1.0, 0.5, 12, 64.0));
}

TEST(EmvaMeasurementTest, RecoversAnImx174LikeSensor) {
  ExpectRecovers(Sensor(0.12, 6.8, 32000.0, 3.0, 0.6, 12, 64.0));
}

TEST(EmvaMeasurementTest, RecoversAHighGainSensorAtSixteenBits) {
  ExpectRecovers(Sensor(1.5, 4.0, 8000.0, 2.0, 1.0, 16, 200.0));
}

TEST(EmvaMeasurementTest, RecoversAnEightBitSensor) {
  ExpectRecovers(Sensor(0.02, 40.0, 10000.0, 50.0, 0.5, 8, 10.0));
}

// A small full well with a wide spread: EMVA's mu_e.sat lies well below the full well (by
// 2 to 3 standard deviations of the signal there), the plateau still finds the full well.
TEST(EmvaMeasurementTest, SmallFullWellsReadLowAtTheVarianceMaximum) {
  const scene::EmvaSensor s = Sensor(1.5, 4.0, 2000.0, 2.0, 2.0, 16, 200.0);
  const EmvaResult r = Measure(s);
  EXPECT_NEAR(r.full_well_e / s.saturation_e, 1.0, kFullWellTolerance);
  EXPECT_LT(r.saturation_e, 0.95 * s.saturation_e);
  EXPECT_GT(r.saturation_e, 0.85 * s.saturation_e);
  ExpectRelative(r.gain_dn_per_e, s.gain_dn_per_e, "K");
}

// The measurement follows the sensor: another K, another measured K (and the same eta).
TEST(EmvaMeasurementTest, ADifferentGainGivesADifferentMeasuredGain) {
  const EmvaResult low = Measure(Sensor(0.2, 3.0, 8000.0, 1.0, 0.5, 12, 64.0));
  const EmvaResult high = Measure(Sensor(0.4, 3.0, 8000.0, 1.0, 0.5, 12, 64.0));
  EXPECT_NEAR(high.gain_dn_per_e / low.gain_dn_per_e, 2.0, 2.0 * kFigureTolerance);
  EXPECT_NEAR(high.saturation_e / low.saturation_e, 1.0, kFigureTolerance);
}

TEST(EmvaMeasurementTest, TooFewPointsOrNoSaturationAreRefused) {
  EmvaSeriesOptions options;
  options.points = 3;
  const SensorModel sensor(Sensor(0.36, 2.3, 10500.0, 1.0, 0.5, 12, 64.0), 7, "emva", 16, 16, 1);
  try {
    MeasureSensor(sensor, options);
    FAIL() << "3 points accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("points must be in [5, 1000], got 3"), std::string::npos)
        << e.what();
  }
  // A series that stops before saturation: its largest variance is its last point.
  std::vector<EmvaPoint> points;
  for (int i = 0; i < 8; ++i) {
    EmvaPoint p;
    p.exposure_s = i * 1e-3;
    p.dark = {64.0, 1.0};
    p.bright = {64.0 + 100.0 * i, 1.0 + 10.0 * i};
    points.push_back(p);
  }
  const StackStats dark{4, 64.0, 0.1, 1.0};
  const StackStats bright{4, 300.0, 2.0, 20.0};
  try {
    EvaluateEmva(points, dark, bright);
    FAIL() << "a series without saturation accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("does not reach saturation"), std::string::npos)
        << e.what();
  }
}

TEST(SensorModelTest, IsDeterministicBitForBit) {
  const scene::EmvaSensor s = Sensor(0.36, 2.3, 10500.0, 1.0, 0.5, 12, 64.0);
  // 512 x 512 x 3 values: exposed in parts on several threads.
  const SensorModel a(s, 11, "left", 512, 512, 3);
  const SensorModel b(s, 11, "left", 512, 512, 3);
  EXPECT_EQ(a.ExposeUniform(3000.0, 5), b.ExposeUniform(3000.0, 5));
  EXPECT_NE(a.ExposeUniform(3000.0, 5), a.ExposeUniform(3000.0, 6));  // temporal noise per frame
  const SensorModel other_camera(s, 11, "right", 512, 512, 3);
  const SensorModel other_seed(s, 12, "left", 512, 512, 3);
  EXPECT_NE(a.ExposeUniform(3000.0, 5), other_camera.ExposeUniform(3000.0, 5));
  EXPECT_NE(a.ExposeUniform(3000.0, 5), other_seed.ExposeUniform(3000.0, 5));
}

TEST(SensorModelTest, ClipsAtTheFullWellAndKeepsDarkNoiseAboveZero) {
  const scene::EmvaSensor s = Sensor(0.36, 2.3, 10500.0, 1.0, 0.5, 12, 64.0);
  const SensorModel sensor(s, 3, "cam", 64, 64, 1);
  const double full_well_dn = std::round(0.36 * 10500.0 + 64.0);  // 3844 DN, below 4095
  for (const uint16_t v : sensor.ExposeUniform(1e6, 0)) ASSERT_EQ(v, full_well_dn);
  // The black level keeps the dark noise off 0 DN.
  const std::vector<uint16_t> dark = sensor.ExposeUniform(0.0, 1);
  EXPECT_EQ(std::count(dark.begin(), dark.end(), uint16_t{0}), 0);
  // A full well beyond the ADC's range: the largest DN.
  const SensorModel adc(Sensor(1.0, 2.0, 10000.0, 0.0, 0.0, 12, 64.0), 3, "cam", 64, 64, 1);
  for (const uint16_t v : adc.ExposeUniform(1e6, 0)) ASSERT_EQ(v, 4095);
}

// K = 1, no dark noise or fixed pattern: the DN are electrons, Poisson distributed (mean =
// variance) in the exact range and in the Gaussian approximation's.
TEST(SensorModelTest, ShotNoiseIsPoisson) {
  scene::EmvaSensor s = Sensor(1.0, 0.0, 60000.0, 0.0, 0.0, 16, 0.0);
  s.quantum_efficiency = 1.0;
  const SensorModel sensor(s, 5, "cam", 64, 64, 1);
  for (const double lambda : {3.0, 40.0, 2000.0}) {
    const std::vector<uint16_t> raw = sensor.ExposeUniform(lambda, 0);
    double sum = 0.0;
    double sum2 = 0.0;
    for (const uint16_t v : raw) {
      sum += v;
      sum2 += static_cast<double>(v) * v;
    }
    const double n = static_cast<double>(raw.size());
    const double mean = sum / n;
    const double variance = sum2 / n - mean * mean;
    EXPECT_NEAR(mean, lambda, 4.0 * std::sqrt(lambda / n)) << lambda;
    EXPECT_NEAR(variance / lambda, 1.0, kVarianceTolerance) << lambda;
  }
}

// --- the AVX2 kernel against the portable loop ----------------------------------------------

// Sensors whose values take every branch: the full well below the ADC's range (and, at gain
// 2.5, above it: max_dn clamps), a full well beyond it, and an 8-bit sensor whose dark noise
// drives values below 0 DN.
std::vector<scene::EmvaSensor> BranchSensors() {
  return {Sensor(0.36, 2.3, 10500.0, 1.0, 0.5, 12, 64.0),
          Sensor(1.0, 2.0, 10000.0, 0.0, 0.0, 12, 64.0),
          Sensor(0.02, 40.0, 10000.0, 50.0, 0.5, 8, 10.0)};
}

// Mean photons for `n` values (eta 0.6): none, negative, the exact Poisson range, mean electrons
// within 2 % of kExactPoissonMean (both sides, PRNU moves them), the Gaussian range and beyond
// the full well.
std::vector<float> BranchPhotons(std::size_t n, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> photons(n);
  const float at_exact = static_cast<float>(kExactPoissonMean / 0.6);
  for (float& p : photons) {
    switch (random() % 6) {
      case 0:
        p = random() % 2 == 0 ? 0.0f : -5.0f;
        break;
      case 1:
        p = 100.0f * unit(random);
        break;
      case 2:
        p = at_exact * (0.98f + 0.04f * unit(random));
        break;
      case 3:
        p = 100.0f + 20000.0f * unit(random);
        break;
      case 4:
        p = 1e5f * (1.0f + 100.0f * unit(random));
        break;
      default:
        p = 30000.0f * unit(random);
        break;
    }
  }
  return photons;
}

// Each value depends on its index alone: 8 or 4 values at a time, the lanes that take a rare
// path (no photons, the exact Poisson range, a Gaussian's two outer bins) redone one by one,
// the last values one by one. Sizes that are no multiples of 4 (and rows of an odd number of
// values); ~12k values a frame: about 3 values in each outer bin (2 / 4096 of them) per
// Gaussian and frame, 6 frames a sensor. Where the CPU lacks AVX2 both are the portable loop.
TEST(SensorModelTest, VectorKernelGivesThePortableLoopsBits) {
  struct Size {
    int width, height, channels;
  };
  // Each vector kernel the CPU has (8 lanes with AVX-512, 4 with AVX2) against the portable.
  for (const int lanes : {8, 4}) {
    for (const scene::EmvaSensor& s : BranchSensors()) {
      for (const Size size :
           {Size{1, 1, 1}, Size{3, 2, 1}, Size{7, 5, 3}, Size{33, 17, 1}, Size{65, 63, 3}}) {
        SCOPED_TRACE(::testing::Message() << lanes << " lanes");
        SensorModel vector(s, 9, "left", size.width, size.height, size.channels);
        UseSensorLanes(vector, lanes);
        SensorModel portable(s, 9, "left", size.width, size.height, size.channels);
        UseSensorLanes(portable, 1);
        const std::size_t n = vector.values();
        const std::vector<float> photons = BranchPhotons(n, static_cast<uint32_t>(n));
        for (const double gain : {1.0, 2.5}) {
          std::vector<uint16_t> fast(n), slow(n);
          vector.Expose(photons.data(), 3, fast.data(), gain);
          portable.Expose(photons.data(), 3, slow.data(), gain);
          ASSERT_EQ(fast, slow) << size.width << " x " << size.height << " x " << size.channels
                                << ", gain " << gain << ", K " << s.gain_dn_per_e;
        }
        // Rendered 8-bit values: 1 ms puts 27 of 255 at kExactPoissonMean, 100 ms saturates.
        Image rendered(size.width, size.height,
                       size.channels == 3 ? PixelFormat::kRgb8 : PixelFormat::kBayerRggb8);
        std::mt19937 random(5);
        for (std::size_t i = 0; i < rendered.size_bytes(); ++i) {
          rendered.data()[i] = static_cast<uint8_t>(random());
        }
        for (const double exposure : {0.001, 0.1}) {
          Image fast8(size.width, size.height, rendered.format());
          Image slow8 = rendered;  // in place
          const std::vector<uint16_t> fast =
              vector.ExposeRendered(rendered.view(), exposure, 4, &fast8, 2.5);
          const std::vector<uint16_t> slow =
              portable.ExposeRendered(slow8.view(), exposure, 4, &slow8, 2.5);
          ASSERT_EQ(fast, slow) << size.width << " x " << size.height << ", " << exposure << " s";
          ASSERT_EQ(std::vector<uint8_t>(fast8.data(), fast8.data() + fast8.size_bytes()),
                    std::vector<uint8_t>(slow8.data(), slow8.data() + slow8.size_bytes()));
          // The 8-bit image is To8Bit's of the raw values.
          Image to8(size.width, size.height, rendered.format());
          vector.To8Bit(fast.data(), &to8);
          ASSERT_EQ(std::vector<uint8_t>(to8.data(), to8.data() + to8.size_bytes()),
                    std::vector<uint8_t>(fast8.data(), fast8.data() + fast8.size_bytes()));
          // ExposeRendered8 (no raw DN kept) writes the same 8-bit image, on both kernels.
          for (const SensorModel* model : {static_cast<const SensorModel*>(&vector),
                                           static_cast<const SensorModel*>(&portable)}) {
            Image only8(size.width, size.height, rendered.format());
            model->ExposeRendered8(rendered.view(), exposure, 4, &only8, 2.5);
            ASSERT_EQ(std::vector<uint8_t>(only8.data(), only8.data() + only8.size_bytes()),
                      std::vector<uint8_t>(fast8.data(), fast8.data() + fast8.size_bytes()));
          }
        }
      }
    }
  }
}

// A frame exposed in chunks on every core (of 2^15 values), the chunks' bounds within rows: the
// same bits both ways.
TEST(SensorModelTest, VectorKernelGivesThePortableLoopsBitsInParts) {
  const scene::EmvaSensor s = BranchSensors()[0];
  const SensorModel vector(s, 2, "right", 723, 731, 1);
  SensorModel portable(s, 2, "right", 723, 731, 1);
  UseSensorLanes(portable, 1);
  const std::vector<float> photons = BranchPhotons(vector.values(), 17);
  std::vector<uint16_t> fast(vector.values()), slow(vector.values());
  vector.Expose(photons.data(), 8, fast.data());
  portable.Expose(photons.data(), 8, slow.data());
  EXPECT_EQ(fast, slow);
  // A rendered mosaic of that size, in chunks of rows: ExposeRendered8 (each run's DN in a
  // buffer of its thread's) writes ExposeRendered's 8-bit image.
  Image rendered(723, 731, PixelFormat::kBayerRggb8);
  std::mt19937 random(11);
  for (std::size_t i = 0; i < rendered.size_bytes(); ++i) {
    rendered.data()[i] = static_cast<uint8_t>(random());
  }
  Image with_raw(723, 731, PixelFormat::kBayerRggb8), only8(723, 731, PixelFormat::kBayerRggb8);
  vector.ExposeRendered(rendered.view(), 0.008, 6, &with_raw);
  vector.ExposeRendered8(rendered.view(), 0.008, 6, &only8);
  EXPECT_EQ(std::vector<uint8_t>(only8.data(), only8.data() + only8.size_bytes()),
            std::vector<uint8_t>(with_raw.data(), with_raw.data() + with_raw.size_bytes()));
}

TEST(SensorModelTest, BadParametersNameTheField) {
  scene::EmvaSensor s;
  s.gain_dn_per_e = -0.5;
  try {
    SensorModel(s, 0, "cam", 8, 8, 1);
    FAIL() << "a negative gain accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("gain_dn_per_e must be a gain in DN per electron in (0, "
                                         "64], got -0.5"),
              std::string::npos)
        << e.what();
  }
  s = scene::EmvaSensor{};
  s.saturation_e = 10.0;  // below 10 x the dark noise of 2.5 e-
  EXPECT_THROW(SensorModel(s, 0, "cam", 8, 8, 1), InvalidArgument);
  EXPECT_THROW(SensorModel(scene::EmvaSensor{}, 0, "cam", 8, 8, 2), InvalidArgument);
}

// --- the renderer's hook: a camera with an emva sensor --------------------------------------

// A camera that sees only the sky, 128 DN in every channel, through an 8-bit sensor of K = 1
// and eta = 1: 204 photons a pixel at full white, so the sky gives 102.4 electrons.
scene::Scene EmvaFlatScene() {
  return scene::Scene::FromYamlString(R"(
background: [0.50196078431372549, 0.50196078431372549, 0.50196078431372549]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
cameras:
  - name: flat
    calibration: {width: 160, height: 120, fx: 100, fy: 100}
    pose: {position: [0, 0, 1]}
    sensor:
      exposure: 0.01
      seed: 5
      emva: {quantum_efficiency: 1, gain_dn_per_e: 1, dark_noise_e: 2, saturation_e: 250,
             bit_depth: 8, black_level_dn: 0, photons_per_second: 20400}
)",
                                      "emva_render_test.yaml",
                                      std::filesystem::temp_directory_path());
}

TEST(SensorRenderTest, RendersTheEmvaSensorOnTheFrameDeterministically) {
  const scene::Scene world = EmvaFlatScene();
  std::unique_ptr<Renderer> renderer = MakeRenderer(world, {});
  const std::vector<Frame> a = renderer->Render(world.InitialState(), 3);
  const std::vector<Frame> b = renderer->Render(world.InitialState(), 4);
  const Image& fa = *a[0].color;
  const Image& fb = *b[0].color;
  const double n = static_cast<double>(fa.size_bytes());
  double sum = 0.0;
  double diff = 0.0;
  double diff2 = 0.0;
  for (std::size_t i = 0; i < fa.size_bytes(); ++i) {
    sum += fa.data()[i];
    const double d = static_cast<double>(fa.data()[i]) - fb.data()[i];
    diff += d;
    diff2 += d * d;
  }
  // Mean: eta mu_p = 128 / 255 * 204 = 102.4 e- = 102.4 DN (standard error ~0.04 DN).
  constexpr double kMeanToleranceDn = 0.3;
  EXPECT_NEAR(sum / n, 102.4, kMeanToleranceDn);
  // Temporal variance: shot (102.4) + dark (4) + rounding (1/12) DN^2.
  const double variance = (diff2 / n - (diff / n) * (diff / n)) / 2.0;
  EXPECT_NEAR(variance / (102.4 + 4.0 + 1.0 / 12.0), 1.0, kVarianceTolerance / 2.0) << variance;
  // The same frame index in a new renderer: the same bits.
  std::unique_ptr<Renderer> again = MakeRenderer(world, {});
  const std::vector<Frame> a2 = again->Render(world.InitialState(), 3);
  EXPECT_EQ(std::vector<uint8_t>(fa.data(), fa.data() + fa.size_bytes()),
            std::vector<uint8_t>(a2[0].color->data(), a2[0].color->data() + fa.size_bytes()));
  // Noise off: the rendered value itself.
  RendererOptions clean;
  clean.noise = false;
  const std::vector<Frame> off = MakeRenderer(world, clean)->Render(world.InitialState(), 3);
  for (std::size_t i = 0; i < off[0].color->size_bytes(); ++i) {
    ASSERT_EQ(off[0].color->data()[i], 128);
  }
}

}  // namespace
}  // namespace saccade::render
