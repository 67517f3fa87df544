// Sensor and lens effects and ground truth (RendererOptions, scene::SensorSpec): noise
// statistics against the configured sigma, determinism by seed, motion blur over the
// exposure, and depth and ids against the scene's analytic geometry through distorted
// lenses (a strong radial-tangential lens and a 190-degree fisheye rendered through a cube).

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "image_camera_helpers.h"
#include "render/gl/internal_color_depth.h"
#include "render/gl/internal_cpu_lens.h"
#include "render/gl/internal_cpu_turn.h"
#include "render/gl/internal_effects.h"
#include "render/gl/internal_pixels.h"
#include "saccade/core/error.h"
#include "saccade/core/image.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/lens_map.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

scene::Scene SceneFrom(const std::string& yaml) {
  return scene::Scene::FromYamlString(yaml, "effects_test.yaml",
                                      std::filesystem::path(SACCADE_SOURCE_DIR) / "scenes");
}

std::vector<Frame> RenderOnce(const scene::Scene& world, const RendererOptions& options = {},
                              const scene::SceneState* state = nullptr, int64_t frame = 0) {
  std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  return renderer->Render(state != nullptr ? *state : world.InitialState(), frame);
}

bool SamePixels(const Image& a, const Image& b) {
  return a.width() == b.width() && a.height() == b.height() &&
         std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

// Writes a failing image for a look, and says where.
std::string Keep(const Image& image, const std::string& name) {
  const auto path = std::filesystem::temp_directory_path() / ("saccade_effects_" + name + ".png");
  WritePng(image.view(), path);
  return path.string();
}

// --- noise -------------------------------------------------------------------------------

// A camera that sees only the sky, of exactly 128 DN, with the given sensor.
std::string FlatScene(const std::string& sensor) {
  return R"(
background: [0.50196078431372549, 0.50196078431372549, 0.50196078431372549]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
cameras:
  - name: flat
    calibration: {width: 640, height: 480, fx: 500, fy: 500}
    pose: {position: [0, 0, 1]}
    sensor: )" +
         sensor + "\n";
}

struct NoiseStats {
  double mean = 0.0;
  double sigma = 0.0;
  double neighbour_correlation = 0.0;  // between horizontally adjacent pixels, one channel
  double channel_correlation = 0.0;    // between R and G of the same pixel
};

NoiseStats Measure(const Image& image, double clean) {
  NoiseStats s;
  const int n = image.width() * image.height() * 3;
  double sum = 0.0, sum2 = 0.0, neighbours = 0.0, channels = 0.0;
  for (int y = 0; y < image.height(); ++y) {
    const uint8_t* row = image.row(y);
    for (int x = 0; x < image.width(); ++x) {
      for (int c = 0; c < 3; ++c) {
        const double d = row[3 * x + c] - clean;
        sum += d;
        sum2 += d * d;
      }
      if (x + 1 < image.width()) neighbours += (row[3 * x] - clean) * (row[3 * x + 3] - clean);
      channels += (row[3 * x] - clean) * (row[3 * x + 1] - clean);
    }
  }
  s.mean = clean + sum / n;
  s.sigma = std::sqrt(sum2 / n);
  const double variance = sum2 / n;
  s.neighbour_correlation = neighbours / (image.height() * (image.width() - 1)) / variance;
  s.channel_correlation = channels / (image.height() * image.width()) / variance;
  return s;
}

struct NoiseCase {
  const char* name;
  double read_noise_dn;
  double gain_dn_per_e;
};

class NoiseTest : public ::testing::TestWithParam<NoiseCase> {};

TEST_P(NoiseTest, MatchesTheConfiguredSigmaWithin2Percent) {
  const NoiseCase& c = GetParam();
  const scene::Scene world =
      SceneFrom(FlatScene("{read_noise_dn: " + std::to_string(c.read_noise_dn) +
                          ", gain_dn_per_e: " + std::to_string(c.gain_dn_per_e) + ", seed: 11}"));
  // In the final pass (a GPU's way) and on the CPU after readback (a software rasteriser's).
  for (const bool on_cpu : {false, true}) {
    SCOPED_TRACE(on_cpu ? "noise on the CPU" : "noise in the final pass");
    RendererOptions options;
    options.noise_on_cpu = on_cpu;
    const std::vector<Frame> frames = RenderOnce(world, options);
    constexpr double kClean = 128.0;
    // Expected: read^2 + K S (EMVA 1288), plus the variance of rounding to whole DN (1/12,
    // Sheppard's correction for a Gaussian much wider than one DN).
    const double expected =
        std::sqrt(c.read_noise_dn * c.read_noise_dn + c.gain_dn_per_e * kClean + 1.0 / 12.0);
    const NoiseStats s = Measure(*frames[0].color, kClean);
    // The issue's bound; 921,600 samples measure sigma to ~0.07 %, so 2 % is a real error.
    constexpr double kSigmaRelativeTolerance = 0.02;
    EXPECT_NEAR(s.sigma / expected, 1.0, kSigmaRelativeTolerance) << s.sigma << " vs " << expected;
    // Zero-mean noise: the mean stays at the signal (standard error ~0.005 DN).
    constexpr double kMeanToleranceDn = 0.05;
    EXPECT_NEAR(s.mean, kClean, kMeanToleranceDn);
    // White: adjacent pixels and channels uncorrelated (standard error ~0.001).
    constexpr double kMaxCorrelation = 0.01;
    EXPECT_LT(std::abs(s.neighbour_correlation), kMaxCorrelation);
    EXPECT_LT(std::abs(s.channel_correlation), kMaxCorrelation);
  }
}

// A lit, textured scene (a ball, a portrait, the checker ground: every DN) seen by one noisy
// camera of `calibration`.
std::string LitScene(const std::string& calibration) {
  return R"(
background: [0.6, 0.7, 0.8]
lights: [{type: ambient, intensity: 0.3}, {type: directional, direction: [1, 0.5, -1]}]
ground: {pattern: checker, cell: 0.25}
objects:
  - {name: ball, kind: sphere, radius: 0.3, pose: {position: [3, 0, 0.5]}, color: [0.9, 0.5, 0.1, 1]}
  - {name: face, kind: picture, image: ../assets/astronaut.png, height: 0.8,
     pose: {position: [3, 0.8, 1.0], rpy_deg: [0, 0, 180]}}
cameras:
  - name: cam
    calibration: )" +
         calibration + R"(
    look_at: {eye: [0, 0, 1.2], target: [3, 0.3, 0.8]}
    sensor: {read_noise_dn: 2, gain_dn_per_e: 0.3, seed: 5}
)";
}

// The noise added on the CPU after readback is the final pass's: the same hash of the pixel
// and frame, the same table entry, the same variance for each DN. On a lit, textured scene
// (every DN, shot noise growing with it) the two images agree to the bit on llvmpipe; a
// device's float rounding of a DN (255 x its texel / 255) may put a rare value on the other
// side of a half.
TEST(NoiseOnCpuTest, AddsTheFinalPassesNoise) {
  const scene::Scene world = SceneFrom(LitScene("{width: 320, height: 240, fx: 300, fy: 300}"));
  RendererOptions options;
  std::unique_ptr<Renderer> pass = MakeRenderer(world, [&] {
    RendererOptions o = options;
    o.noise_on_cpu = false;
    return o;
  }());
  options.noise_on_cpu = true;
  std::unique_ptr<Renderer> cpu = MakeRenderer(world, options);
  // Large enough to be converted in chunks of rows on threads: each chunk's rows keep their
  // place in the pass's hash.
  EXPECT_GE(320u * 240u, gl::kMinSplitNoisePixels);
  const scene::SceneState state = world.InitialState();
  const std::shared_ptr<const Image> a = pass->Render(state, 3)[0].color;
  const std::shared_ptr<const Image> b = cpu->Render(state, 3)[0].color;
  ASSERT_EQ(a->size_bytes(), b->size_bytes());
  std::size_t differ = 0;
  int worst = 0;
  for (std::size_t i = 0; i < a->size_bytes(); ++i) {
    const int d = std::abs(a->data()[i] - b->data()[i]);
    differ += d != 0;
    worst = std::max(worst, d);
  }
  EXPECT_LE(worst, 1);
  EXPECT_LT(static_cast<double>(differ) / a->size_bytes(), 1e-3) << differ << " values differ";
  RendererOptions clean = options;
  clean.noise = false;
  EXPECT_FALSE(SamePixels(*b, *MakeRenderer(world, clean)->Render(state, 3)[0].color));
}

// The lens remapped on the CPU after the source view is read back (a software rasteriser's
// way) is the final pass's: the same bilinear samples of the same map, within one DN (the pass
// rounds each of a pixel's footprint samples to 8 bits, the CPU their mean once), with and
// without noise. Two lenses of one source view: the bench scene's barrel (one sample a pixel)
// and a barrel so strong that it folds before the corners, so that the image's rim takes
// several samples a pixel and its corners have no ray (black).
TEST(LensOnCpuTest, RemapsAsTheFinalPassDoes) {
  const std::string cameras[] = {
      "{width: 320, height: 240, fx: 300, fy: 300, distortion: {model: radtan, coefficients: "
      "[-0.2, 0.1, 0.0005, -0.0003, 0.0]}}",
      "{width: 320, height: 240, fx: 200, fy: 200, distortion: {model: radtan, coefficients: "
      "[-0.45, 0.0, 0.0, 0.0, 0.0]}}"};
  for (const std::string& calibration : cameras) {
    SCOPED_TRACE(calibration);
    const scene::Scene world = SceneFrom(LitScene(calibration));
    const geometry::LensMap lens = geometry::MakeLensMap(world.cameras()[0].model);
    ASSERT_EQ(lens.kind, geometry::LensMap::Kind::kPinhole);
    const gl::RemapTable table = gl::MakeRemapTable(lens);
    const scene::SceneState state = world.InitialState();
    for (const bool noise : {false, true}) {
      SCOPED_TRACE(noise ? "with noise" : "without noise");
      RendererOptions options;
      options.noise = noise;
      options.lens_on_cpu = false;
      const std::shared_ptr<const Image> pass = RenderOnce(world, options, &state, 3)[0].color;
      options.lens_on_cpu = true;
      const std::shared_ptr<const Image> cpu = RenderOnce(world, options, &state, 3)[0].color;
      ASSERT_EQ(pass->size_bytes(), cpu->size_bytes());
      std::size_t differ = 0;
      int worst = 0;
      int64_t sum = 0;
      for (std::size_t i = 0; i < pass->size_bytes(); ++i) {
        const int d = cpu->data()[i] - pass->data()[i];
        differ += d != 0;
        worst = std::max(worst, std::abs(d));
        sum += d;
      }
      // A sample's rounding differs here and there (the rasteriser truncates its weights and
      // each stage of the blend), by one DN, two where two roundings meet on an edge (a
      // misplaced sample, a half-pixel or a row's shift, would differ by tens on every edge);
      // noise adds no more (the same deviate on neighbouring DNs); and no bias.
      EXPECT_LE(worst, 2) << Keep(*pass, "lens_pass") << " " << Keep(*cpu, "lens_cpu");
      EXPECT_LT(static_cast<double>(differ) / pass->size_bytes(), 0.05) << differ << " differ";
      EXPECT_LT(std::abs(static_cast<double>(sum) / pass->size_bytes()), 0.02) << sum;
      // The lens is applied: not the pinhole's image.
      options.distortion = false;
      EXPECT_FALSE(SamePixels(*cpu, *RenderOnce(world, options, &state, 3)[0].color));
    }
    if (lens.invalid_pixels > 0) {  // the folding lens: several samples a pixel, and no ray
      EXPECT_GT(table.multi_tap_pixels, 1000);
      EXPECT_GT(lens.invalid_pixels, 0);
      gl::CpuLens cpu_lens(table, lens.width, lens.height, lens.views[0].intrinsics.width(),
                           lens.views[0].intrinsics.height());
      EXPECT_GT(cpu_lens.special_pixels(), static_cast<std::size_t>(table.multi_tap_pixels));
    }
  }
}

// A large batch's readback converts RGBA to RGB in parts on threads (RenderBatch): the same
// bytes as one pass, whatever the number of parts and wherever a part ends (a pixel count that
// no part divides, an SSSE3 store of 16 bytes near each part's end).
TEST(PixelsTest, RgbaToRgbInPartsGivesTheSameBytesAsOnePass) {
  for (const std::size_t pixels :
       {std::size_t{5}, gl::kMinConvertPartPixels - 1, 3 * gl::kMinConvertPartPixels + 7}) {
    std::vector<uint8_t> rgba(4 * pixels);
    uint32_t x = 12345u;
    for (uint8_t& b : rgba) {
      x = x * 1664525u + 1013904223u;
      b = static_cast<uint8_t>(x >> 24);
    }
    std::vector<uint8_t> want(3 * pixels);
    gl::RgbaToRgb(rgba.data(), want.data(), pixels);
    for (const unsigned threads : {1u, 2u, 3u, 8u, 64u}) {
      std::vector<uint8_t> got(3 * pixels + 16, 0xAB);  // a guard past the end
      gl::RgbaToRgbInParts(rgba.data(), got.data(), pixels, threads);
      EXPECT_EQ(std::memcmp(got.data(), want.data(), want.size()), 0) << pixels << " " << threads;
      EXPECT_EQ(got[3 * pixels], 0xAB) << "wrote past the end";
    }
  }
  // Alpha is dropped, channels kept in order.
  const uint8_t one[4] = {10, 20, 30, 40};
  uint8_t rgb[3] = {};
  gl::RgbaToRgbInParts(one, rgb, 1, 4);
  EXPECT_EQ(rgb[0], 10);
  EXPECT_EQ(rgb[1], 20);
  EXPECT_EQ(rgb[2], 30);
}

// The remap's, the depth remap's, the camera z's and the noise's vector loops and their
// portable ones give the same rows to the bit, on a random source through the barrel lens, in
// rows of a width that leaves a tail for the portable loop: the remap's integer arithmetic, the
// depth remap's float blends and edges, the camera z's divisions in double (and 0 where nothing
// was drawn), and the noise's levels (a table) against
// the vector loop's float arithmetic, for read noise alone, shot noise alone, both, and noise
// wide enough to clip at 0 and 255.
TEST(LensOnCpuTest, TheVectorLoopsEqualThePortableOnes) {
  const double coefficients[] = {-0.2, 0.1, 0.0005, -0.0003, 0.0};
  const geometry::CameraModel model(geometry::Intrinsics(317, 240, 300, 300, 158, 119.5),
                                    geometry::Distortion::RadialTangential(coefficients));
  const geometry::LensMap lens = geometry::MakeLensMap(model);
  const int w = lens.views[0].intrinsics.width(), h = lens.views[0].intrinsics.height();
  std::vector<uint8_t> source(4 * static_cast<std::size_t>(w) * h);
  uint32_t state = 12345;
  for (uint8_t& b : source) {
    b = static_cast<uint8_t>((state = state * 1664525u + 1013904223u) >> 24);
  }
  const gl::CpuLens cpu_lens(gl::MakeRemapTable(lens), lens.width, lens.height, w, h);
  std::vector<uint8_t> fast(4 * lens.width), portable(4 * lens.width);
  for (int y = 0; y < lens.height; ++y) {
    cpu_lens.RemapRow(source.data(), y, fast.data());
    cpu_lens.RemapRow(source.data(), y, portable.data(), /*simd=*/false);
    ASSERT_EQ(fast, portable) << "row " << y;
  }
  // The depth remap: blocks of surfaces (smooth slopes within 2 %, steps between blocks, no
  // surface in some), so that rows take both the bilinear and the nearest branch.
  std::vector<float> z(static_cast<std::size_t>(w) * h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int block = (u / 23) * 7 + v / 17;
      z[static_cast<std::size_t>(v) * w + u] =
          block % 5 == 0 ? 0.0f : 0.5f + 0.3f * static_cast<float>(block % 11) + 1e-3f * u;
    }
  }
  std::vector<float> sorted_z = z;
  std::sort(sorted_z.begin(), sorted_z.end());
  std::vector<float> fast_z(lens.width), portable_z(lens.width);
  std::size_t blended = 0;
  for (int y = 0; y < lens.height; ++y) {
    cpu_lens.RemapDepthRow(z.data(), y, fast_z.data());
    cpu_lens.RemapDepthRow(z.data(), y, portable_z.data(), /*simd=*/false);
    ASSERT_EQ(std::memcmp(fast_z.data(), portable_z.data(), 4 * fast_z.size()), 0) << "row " << y;
    for (const float value : fast_z) {  // a value of no source pixel: bilinear
      blended += !std::binary_search(sorted_z.begin(), sorted_z.end(), value);
    }
  }
  EXPECT_GT(blended, std::size_t{1000});
  // The colour pass's window depth to the camera's z: depths across [0, 1] (near, far, the
  // far plane's 1 where nothing was drawn) through a view turned off the camera's axis.
  Eigen::Matrix3d R_CV =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
  projection(2, 2) = -(50.0 + 0.05) / (50.0 - 0.05);  // near 5 cm, far 50 m
  projection(2, 3) = -2.0 * 50.0 * 0.05 / (50.0 - 0.05);
  const gl::ColorDepthMap depth_map =
      gl::MakeColorDepthMap(projection, R_CV, lens.views[0].intrinsics);
  std::vector<float> window(static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < window.size(); ++i) {
    state = state * 1664525u + 1013904223u;
    window[i] = i % 9 == 0 ? 1.0f : static_cast<float>(state >> 8) / 16777216.0f;
  }
  std::vector<float> fast_camera_z(window.size()), portable_camera_z(window.size());
  gl::CameraZRows(depth_map, window.data(), 0, h, fast_camera_z.data());
  gl::CameraZRows(depth_map, window.data(), 0, h, portable_camera_z.data(), /*simd=*/false);
  EXPECT_EQ(std::memcmp(fast_camera_z.data(), portable_camera_z.data(), 4 * window.size()), 0);
  EXPECT_EQ(std::count(fast_camera_z.begin(), fast_camera_z.end(), 0.0f),
            std::count(window.begin(), window.end(), 1.0f));
  const std::pair<float, float> sensors[] = {
      {5.0f, 0.0f}, {0.0f, 0.2f}, {2.0f, 0.3f}, {1.5f, 0.1f}, {20.0f, 1.7f}};
  for (const auto& [read, gain] : sensors) {
    SCOPED_TRACE(::testing::Message() << "read " << read << " DN, gain " << gain);
    const std::vector<uint8_t> levels = gl::NoiseLevels(read, gain);
    const gl::CpuNoise noise{77, read, gain, gl::PackedGaussianTable().data(), levels.data()};
    std::vector<uint8_t> fast_rgb(3 * lens.width), portable_rgb(3 * lens.width);
    std::size_t noisy = 0;
    for (int y = 0; y < lens.height; ++y) {
      cpu_lens.RemapRow(source.data(), y, fast.data());
      gl::RgbaRowToRgbWithNoise(fast.data(), fast_rgb.data(), lens.width, y, noise);
      gl::RgbaRowToRgbWithNoise(fast.data(), portable_rgb.data(), lens.width, y, noise,
                                /*simd=*/false);
      ASSERT_EQ(fast_rgb, portable_rgb) << "row " << y;
      for (int x = 0; x < lens.width; ++x) noisy += fast_rgb[3 * x] != fast[4 * x];
    }
    EXPECT_GT(noisy, static_cast<std::size_t>(lens.width) * lens.height / 2);  // noise added
  }
}

INSTANTIATE_TEST_SUITE_P(Sensor, NoiseTest,
                         ::testing::Values(NoiseCase{"read", 5.0, 0.0}, NoiseCase{"shot", 0.0, 0.2},
                                           NoiseCase{"read_and_shot", 2.0, 0.1},
                                           NoiseCase{"small_read", 1.5, 0.0}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(NoiseSeedTest, SameSeedSameFramesOtherSeedFrameOrCameraOtherNoise) {
  const std::string sensor = "{read_noise_dn: 3, seed: 7}";
  const scene::Scene world = SceneFrom(FlatScene(sensor));
  const std::vector<Frame> a = RenderOnce(world);
  const std::vector<Frame> b = RenderOnce(world);  // another renderer, same seed
  EXPECT_TRUE(SamePixels(*a[0].color, *b[0].color));

  const std::vector<Frame> other_seed =
      RenderOnce(SceneFrom(FlatScene("{read_noise_dn: 3, seed: 8}")));
  EXPECT_FALSE(SamePixels(*a[0].color, *other_seed[0].color));

  const scene::SceneState state = world.InitialState();
  const std::vector<Frame> next_frame = RenderOnce(world, {}, &state, 1);
  EXPECT_FALSE(SamePixels(*a[0].color, *next_frame[0].color));

  // Two cameras with the same seed draw different noise (the name is part of the stream).
  std::string two = FlatScene(sensor);
  two += R"(  - name: flat2
    calibration: {width: 640, height: 480, fx: 500, fy: 500}
    pose: {position: [0, 0, 1]}
    sensor: )" +
         sensor + "\n";
  const std::vector<Frame> pair = RenderOnce(SceneFrom(two));
  EXPECT_TRUE(SamePixels(*pair[0].color, *a[0].color));
  EXPECT_FALSE(SamePixels(*pair[0].color, *pair[1].color));
}

TEST(NoiseSwitchTest, NoiseOffGivesTheCleanSignal) {
  const scene::Scene world = SceneFrom(FlatScene("{read_noise_dn: 4, gain_dn_per_e: 0.5}"));
  RendererOptions options;
  options.noise = false;
  const std::vector<Frame> frames = RenderOnce(world, options);
  const Image& image = *frames[0].color;
  for (std::size_t i = 0; i < image.size_bytes(); ++i) ASSERT_EQ(image.data()[i], 128) << i;
}

// --- motion blur ---------------------------------------------------------------------------

// A white box on black, moving along +y (to the left in the camera's image... see below) at
// `speed` m/s, 2 m in front of a world camera looking along +x.
std::string MovingBoxScene(double speed, const std::string& sensor) {
  return R"(
background: [0, 0, 0]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
objects:
  - name: box
    kind: box
    size: [0.05, 0.4, 0.4]
    color: [1, 1, 1, 1]
    motion: {type: constant_velocity, linear: [0, )" +
         std::to_string(speed) + R"(, 0]}
    pose: {position: [2, 0, 1]}
cameras:
  - name: cam
    calibration: {width: 320, height: 240, fx: 400, fy: 400}
    look_at: {eye: [0, 0, 1], target: [2, 0, 1]}
    sensor: )" +
         sensor + "\n";
}

// Mean intensity (red) of column x over the middle rows.
double Column(const Image& image, int x) {
  double sum = 0.0;
  for (int y = 100; y < 140; ++y) sum += image.row(y)[3 * x];
  return sum / 40.0;
}

TEST(MotionBlurTest, StillSceneWithExposureRendersExactlyAsAnInstant) {
  const scene::Scene with = SceneFrom(MovingBoxScene(0.0, "{exposure: 0.02, blur_samples: 8}"));
  const scene::Scene without = SceneFrom(MovingBoxScene(0.0, "{exposure: 0}"));
  EXPECT_TRUE(SamePixels(*RenderOnce(with)[0].color, *RenderOnce(without)[0].color));
}

TEST(MotionBlurTest, MovingObjectSmearsOverItsPathDuringTheExposure) {
  // 1 m/s for 20 ms at 2 m (well, the front face at 1.975 m) with f = 400 px: the box moves
  // 400 * 0.02 / 1.975 = 4.05 px; +y in the world is -x in this camera's image.
  constexpr double kSpeed = 1.0, kExposure = 0.02, kFocal = 400.0, kDepth = 1.975;
  const double path_px = kFocal * kSpeed * kExposure / kDepth;
  const scene::Scene world =
      SceneFrom(MovingBoxScene(kSpeed, "{exposure: 0.02, blur_samples: 16}"));
  RendererOptions options;
  options.msaa_samples = 4;  // coverage, for edge positions better than a pixel
  const std::shared_ptr<const Image> blurred_image = RenderOnce(world, options)[0].color;
  const Image& blurred = *blurred_image;
  RendererOptions sharp_options = options;
  sharp_options.motion_blur = false;
  const std::shared_ptr<const Image> sharp_image = RenderOnce(world, sharp_options)[0].color;
  const Image& sharp = *sharp_image;

  // The box's left edge (in the image): the ramp from black to white.
  const double half_width_px = kFocal * 0.2 / kDepth;
  const double edge = (320 - 1) / 2.0 - half_width_px;  // at t = 0, the middle of the exposure
  // Sharp: a one-pixel ramp. Blurred: the integral of the moving edge, a ramp as wide as the
  // path, centred on the edge at mid-exposure. Its width from the 10 % to the 90 % level is
  // 0.8 of the path; its centre is where the coverage is 50 %.
  const auto ramp = [&](const Image& image, double* centre, double* width) {
    double x10 = -1, x50 = -1, x90 = -1;
    for (int x = 0; x + 1 < 320; ++x) {
      const double a = Column(image, x) / 255.0, b = Column(image, x + 1) / 255.0;
      const auto cross = [&](double level, double* out) {
        if (*out < 0 && a < level && b >= level) *out = x + (level - a) / (b - a);
      };
      cross(0.1, &x10);
      cross(0.5, &x50);
      cross(0.9, &x90);
    }
    *centre = x50;
    *width = x90 - x10;
  };
  double sharp_centre, sharp_width, blur_centre, blur_width;
  ramp(sharp, &sharp_centre, &sharp_width);
  ramp(blurred, &blur_centre, &blur_width);
  // Position and width of a box-filtered edge, 16 samples: ~0.1 px discretisation, plus the
  // pixel's own footprint (1 px box, adds < 0.2 px to the width of a 4 px ramp).
  constexpr double kEdgeTolerancePx = 0.3;
  EXPECT_NEAR(sharp_centre, edge, kEdgeTolerancePx);
  // A sharp edge: one or two pixels of partial coverage (4 MSAA samples).
  EXPECT_LT(sharp_width, 2.0);
  EXPECT_NEAR(blur_centre, edge, kEdgeTolerancePx) << Keep(blurred, "blur");
  EXPECT_NEAR(blur_width, 0.8 * path_px, 2 * kEdgeTolerancePx) << Keep(blurred, "blur");
}

// A still camera with a lens, a checkered floor and a still ball, and `mover` (an object's
// YAML, without its name) crossing at 2 m/s at 2.5 m: the blur redraws only the mover's sweep
// after the first sub-frame. The frame must be the mean of its sub-frames' instants, each
// drawn whole without blur. `max_samples`: the most sub-frames the mover's motion bound may
// ask for; `max_difference_dn`: the largest difference from the mean of the instants.
void ExpectRedrawingOnlyWhatMovesGivesTheMeanOfTheInstants(const std::string& mover,
                                                           const std::string& label,
                                                           int max_samples = 8,
                                                           int max_difference_dn = 1) {
  SCOPED_TRACE(label);
  const scene::Scene world = SceneFrom(R"(
background: [0.3, 0.4, 0.5]
lights: [{type: ambient, intensity: 0.5}, {type: directional, direction: [1, 0.5, -1]}]
ground: {pattern: checker, cell: 0.25}
objects:
  - {name: ball, kind: sphere, radius: 0.2, pose: {position: [3, -0.6, 0.5]}, color: [0.9, 0.2, 0.1, 1]}
  - name: mover
    )" + mover + R"(
    motion: {type: constant_velocity, linear: [0, 2, 0]}
    pose: {position: [2.5, 0, 0.8]}
cameras:
  - name: cam
    calibration: {width: 320, height: 240, fx: 300, fy: 300,
                  distortion: {model: radtan, coefficients: [-0.2, 0.05, 0, 0, 0]}}
    look_at: {eye: [0, 0, 1.2], target: [3, 0, 0.6]}
    sensor: {exposure: 0.02, blur_samples: 16}
)");
  constexpr double kExposure = 0.02;
  const scene::SceneState state = world.InitialState();
  const std::shared_ptr<const Image> blurred = RenderOnce(world, {}, &state)[0].color;
  const int n = blurred->metadata().exposure_samples;
  // 2 m/s for 20 ms at 2.5 m through f = 300 px: about 5 px of motion.
  EXPECT_GE(n, 4);
  EXPECT_LE(n, max_samples);
  RendererOptions sharp;
  sharp.motion_blur = false;
  std::unique_ptr<Renderer> reference = MakeRenderer(world, sharp);
  std::vector<double> mean(blurred->size_bytes(), 0.0);
  std::shared_ptr<const Image> first;
  for (int k = 0; k < n; ++k) {
    scene::SceneState instant = state;
    instant.time += kExposure * ((k + 0.5) / n - 0.5);
    const std::shared_ptr<const Image> image = reference->Render(instant, 0)[0].color;
    if (k == 0) first = image;
    for (std::size_t i = 0; i < mean.size(); ++i) mean[i] += image->data()[i] / double(n);
  }
  int worst = 0;
  double sum = 0.0;
  for (std::size_t i = 0; i < mean.size(); ++i) {
    const int d = std::abs(blurred->data()[i] - static_cast<int>(std::floor(mean[i] + 0.5)));
    worst = std::max(worst, d);
    sum += d;
  }
  // The blur filters its float sum through the lens, the instants their 8-bit images: the
  // texture unit's 8-bit weights round the two differently, by at most 1 DN (1.5 % of the
  // values here; 2 DN through a picture's texture). A sub-frame missing from part of the box's
  // sweep would be off by tens of DN.
  constexpr double kMeanDifferenceDn = 0.05;
  EXPECT_LE(worst, max_difference_dn) << Keep(*blurred, "region_blur_" + label);
  EXPECT_LT(sum / mean.size(), kMeanDifferenceDn) << Keep(*blurred, "region_blur_" + label);
  EXPECT_FALSE(SamePixels(*blurred, *first));  // the mover did smear
}

TEST(MotionBlurTest, RedrawingOnlyWhatMovesGivesTheMeanOfTheInstants) {
  ExpectRedrawingOnlyWhatMovesGivesTheMeanOfTheInstants(
      "kind: box\n    size: [0.1, 0.1, 0.1]\n    color: [1, 1, 1, 1]", "box");
  // A sphere's region is bounded by its radius, not its box's half diagonal (sqrt(3) times
  // as large): a region short of its silhouette would leave its edge unblurred (with half
  // the radius: 75 DN off).
  ExpectRedrawingOnlyWhatMovesGivesTheMeanOfTheInstants(
      "kind: sphere\n    radius: 0.08\n    color: [1, 1, 1, 1]", "sphere");
  // Flat items: the region is also bounded by the hull of their model's box, far inside their
  // sphere's (a picture's sphere reaches half its diagonal in front of it and behind). A box
  // hull short of the drawn item would cut the smear (shrunk to 0.7 of its size: the picture
  // 95 DN off, the slab 77): a picture, a thin slab, and the mug (an OBJ in centimetres, its box
  // scaled by unit_scale as it is drawn). Their spheres' motion bound asks for a sub-frame more
  // than the small movers'.
  ExpectRedrawingOnlyWhatMovesGivesTheMeanOfTheInstants(
      "kind: picture\n    image: ../assets/astronaut.png\n    height: 0.4", "picture", 10, 2);
  ExpectRedrawingOnlyWhatMovesGivesTheMeanOfTheInstants(
      "kind: box\n    size: [0.02, 0.4, 0.3]\n    color: [1, 1, 1, 1]", "slab", 10);
  ExpectRedrawingOnlyWhatMovesGivesTheMeanOfTheInstants(
      "kind: model\n    file: ../assets/mug/mug.obj\n    unit_scale: 0.01\n"
      "    texture: ../assets/mug/mug.png",
      "mug");
}

// The POPEYE head 1.2 m high before a checker floor and a red ball 2 m ahead, its eyes
// exposed 10 ms in up to `blur_samples` sub-frames; `ball_motion` (YAML, e.g. "{type:
// constant_velocity, linear: [0, -2, 0]}") moves the ball.
std::string HeadAndBallScene(int blur_samples, const std::string& ball_motion = "") {
  const std::string motion = ball_motion.empty() ? "" : ", motion: " + ball_motion;
  const std::string sensor =
      "{sensor: {exposure: 0.01, blur_samples: " + std::to_string(blur_samples) + "}}";
  return R"(
background: [0.6, 0.7, 0.8]
lights: [{type: ambient, intensity: 0.4}, {type: directional, direction: [1, 0, -1]}]
ground: {pattern: checker, cell: 0.25}
objects:
  - {name: ball, kind: sphere, radius: 0.2, pose: {position: [2, 0.3, 1.2]}, color: [0.9, 0.2, 0.1, 1])" +
         motion + R"(}
robot:
  head: ../robots/popeye.yaml
  pose: {position: [0, 0, 1.2]}
  cameras:
    left: )" +
         sensor + R"(
    right: )" +
         sensor + "\n";
}

TEST(MotionBlurTest, ASaccadeDuringTheExposureBlursTheEyesAStillHeadDoesNot) {
  const scene::Scene world = SceneFrom(HeadAndBallScene(8));
  scene::SceneState still = world.InitialState();
  RendererOptions no_blur;
  no_blur.motion_blur = false;
  std::unique_ptr<Renderer> renderer = MakeRenderer(world);
  std::unique_ptr<Renderer> reference = MakeRenderer(world, no_blur);
  const std::vector<Frame> still_frames = renderer->Render(still, 0);
  const std::vector<Frame> sharp_frames = reference->Render(still, 0);
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(SamePixels(*still_frames[i].color, *sharp_frames[i].color)) << i;
    EXPECT_EQ(still_frames[i].color->metadata().exposure_samples, 1) << i;
  }
  // A saccade: pan at 5 rad/s (about 290 deg/s) over 10 ms moves the image by ~0.05 rad,
  // ~60 px at f = 1290 px. The blurred image differs from the sharp one of the same instant,
  // and is smoother: its mean absolute horizontal gradient falls.
  scene::SceneState moving = still;
  moving.joint_velocities[0] = 5.0;
  const std::vector<Frame> blurred = renderer->Render(moving, 1);
  const std::vector<Frame> sharp = reference->Render(moving, 1);
  for (int i = 0; i < 2; ++i) {
    const Image& b = *blurred[i].color;
    const Image& s = *sharp[i].color;
    EXPECT_FALSE(SamePixels(b, s)) << i;
    const auto gradient = [](const Image& image) {
      double sum = 0.0;
      for (int y = 0; y < image.height(); y += 4) {
        const uint8_t* row = image.row(y);
        for (int x = 0; x + 1 < image.width(); ++x) {
          const double d = row[3 * x + 3] - row[3 * x];
          sum += d * d;
        }
      }
      return sum;
    };
    // Energy of the horizontal gradient (squared: a blurred step keeps its total variation
    // but spreads it): a step of height h smeared over n pixels keeps h^2 / n of it. Over
    // ~60 px, far less than half remains.
    EXPECT_LT(gradient(b), 0.5 * gradient(s)) << Keep(b, "saccade");
    EXPECT_EQ(b.metadata().exposure_samples, 8) << i;  // the scene's limit
  }

  // Blur takes what the motion needs: a pan that moves the image centre by a third of a
  // pixel over the exposure is drawn as one instant (the sharp image); one that moves it by
  // 4 px takes at least 4 sub-frames (no ghost step over a pixel) but not the limit.
  const double f = world.FindCamera("left")->model.intrinsics().fx();
  const double exposure = 0.01;
  for (const auto& [centre_px, least, most] : {std::tuple{0.33, 1, 1}, std::tuple{4.0, 4, 7}}) {
    SCOPED_TRACE("image motion at the centre " + std::to_string(centre_px) + " px");
    scene::SceneState panning = still;
    panning.joint_velocities[0] = centre_px / (f * exposure);
    const std::vector<Frame> got = renderer->Render(panning, 2);
    const std::vector<Frame> instant = reference->Render(panning, 2);
    for (int i = 0; i < 2; ++i) {
      const int n = got[i].color->metadata().exposure_samples;
      EXPECT_GE(n, least) << i;
      EXPECT_LE(n, most) << i;
      EXPECT_EQ(SamePixels(*got[i].color, *instant[i].color), n == 1) << i;
    }
  }
}

// A turning camera blurs through its turn (RendererOptions::turn_blur: a few drawn instants
// seen through the homographies of the sub-frames' orientations) as drawing every sub-frame
// does. The eyes turning about their centres is a pure turn, one instant: the two agree within
// the bilinear resampling, away from the borders (where the turned view reaches past the drawn
// one, whose edge is then repeated).
TEST(MotionBlurTest, ATurningCameraBlursThroughItsTurnAsDrawingEverySubFrameDoes) {
  const scene::Scene world = SceneFrom(HeadAndBallScene(16));
  RendererOptions drawn;
  drawn.turn_blur = false;
  drawn.noise = false;
  RendererOptions turned = drawn;
  turned.turn_blur = true;
  std::unique_ptr<Renderer> reference = MakeRenderer(world, drawn);
  std::unique_ptr<Renderer> renderer = MakeRenderer(world, turned);
  // Mean absolute difference (DN) inside a margin of `margin` pixels, and the share of
  // values that differ by more than 8 DN.
  const auto compare = [](const Image& a, const Image& b, int margin) {
    double sum = 0.0;
    int64_t n = 0, over = 0;
    for (int y = margin; y < a.height() - margin; ++y) {
      for (int x = 3 * margin; x < 3 * (a.width() - margin); ++x) {
        const int d = std::abs(int(a.row(y)[x]) - int(b.row(y)[x]));
        sum += d;
        over += d > 8 ? 1 : 0;
        ++n;
      }
    }
    return std::pair{sum / static_cast<double>(n), static_cast<double>(over) / n};
  };

  // Both eyes turning at 2 rad/s (115 deg/s) over 10 ms: ~26 px of image motion.
  scene::SceneState turning = world.InitialState();
  turning.joint_velocities[2] = 2.0;
  turning.joint_velocities[3] = -2.0;
  const std::vector<Frame> want = reference->Render(turning, 0);
  const std::vector<Frame> got = renderer->Render(turning, 0);
  for (int i = 0; i < 2; ++i) {
    const Image& a = *got[i].color;
    const Image& b = *want[i].color;
    EXPECT_EQ(a.metadata().exposure_samples, b.metadata().exposure_samples) << i;
    EXPECT_GE(a.metadata().exposure_samples, 8) << i;
    EXPECT_FALSE(SamePixels(a, b)) << i;  // the other path: resampled, not drawn
    // Measured: 0.08 DN on average. The drawn sub-frames are not anti-aliased: an edge pixel
    // whose coverage flips in one of the 16 sub-frames moves by 1/16 of the edge's contrast
    // (up to 30 DN here), so a few edge pixels differ by more than 8 DN.
    const auto [mean, over] = compare(a, b, 40);
    EXPECT_LT(mean, 0.25) << i << Keep(a, "turned") << Keep(b, "drawn");
    EXPECT_LT(over, 0.005) << i;
  }

  // The neck turning shifts the eyes too (0.1 m from its axis): the shift's parallax is
  // bounded (conservatively: the ground straight below the eyes) and the exposure is cut into
  // as many stretches, each drawn at its middle, as keep a sub-frame within
  // turn_blur_max_error_px of drawing it: at 1 rad/s one, at 5 rad/s more. Both stay within
  // 0.25 DN of drawing every sub-frame; a bound of 0 draws every one, bit for bit.
  RendererOptions exact = turned;
  exact.turn_blur_max_error_px = 0.0;
  std::unique_ptr<Renderer> exact_renderer = MakeRenderer(world, exact);
  for (const double pan : {1.0, 5.0}) {
    SCOPED_TRACE("neck pan " + std::to_string(pan) + " rad/s");
    scene::SceneState panning = world.InitialState();
    panning.joint_velocities[0] = pan;
    const std::vector<Frame> all = reference->Render(panning, 1);
    const std::vector<Frame> bounded = renderer->Render(panning, 1);
    const std::vector<Frame> zero = exact_renderer->Render(panning, 1);
    for (int i = 0; i < 2; ++i) {
      EXPECT_TRUE(SamePixels(*zero[i].color, *all[i].color)) << i;
      EXPECT_FALSE(SamePixels(*bounded[i].color, *all[i].color)) << i;
      const auto [mean, over] = compare(*bounded[i].color, *all[i].color, 60);
      EXPECT_LT(mean, 0.25) << i;
      EXPECT_LT(over, 0.005) << i;
    }
  }

  // The neck tilting turns the images vertically: the homographies act on image rows (row 0 at
  // the top, as the scene passes draw), which a turn about a vertical axis alone would not show.
  {
    scene::SceneState tilting = world.InitialState();
    tilting.joint_velocities[1] = 1.0;
    const std::vector<Frame> all = reference->Render(tilting, 2);
    const std::vector<Frame> got_tilt = renderer->Render(tilting, 2);
    for (int i = 0; i < 2; ++i) {
      EXPECT_GE(all[i].color->metadata().exposure_samples, 2) << i;
      EXPECT_FALSE(SamePixels(*got_tilt[i].color, *all[i].color)) << i;
      const auto [mean, over] = compare(*got_tilt[i].color, *all[i].color, 60);
      EXPECT_LT(mean, 0.25) << i;
      EXPECT_LT(over, 0.005) << i;
    }
  }

  // The ball rolling 2 m/s across the view while the eyes turn: the turn cannot explain the
  // ball's own motion (about 5 px over the exposure), so the exposure is cut into stretches
  // and the ball smears over its path as when every sub-frame is drawn; one instant for the
  // whole exposure (a bound opened wide) leaves it sharp, many times further off.
  const scene::Scene world2 =
      SceneFrom(HeadAndBallScene(16, "{type: constant_velocity, linear: [0, -2, 0]}"));
  RendererOptions wide = turned;
  wide.turn_blur_max_error_px = 100.0;
  const std::vector<Frame> drawn2 = MakeRenderer(world2, drawn)->Render(turning, 0);
  const std::vector<Frame> turned2 = MakeRenderer(world2, turned)->Render(turning, 0);
  const std::vector<Frame> wide2 = MakeRenderer(world2, wide)->Render(turning, 0);
  for (int i = 0; i < 2; ++i) {
    const auto [mean, over] = compare(*turned2[i].color, *drawn2[i].color, 40);
    const auto [wide_mean, wide_over] = compare(*wide2[i].color, *drawn2[i].color, 40);
    EXPECT_FALSE(SamePixels(*turned2[i].color, *drawn2[i].color)) << i;
    EXPECT_LT(mean, 0.25) << i;
    EXPECT_LT(over, 0.005) << i;
    // Measured: 0.05 DN and 0.17 % of values over 8 DN, against 0.40 DN and 1.6-1.9 % with
    // the ball left sharp. (Its 8 stretches, more than the final pass takes, accumulate.)
    EXPECT_GT(wide_over, 3.0 * over) << i;
  }

  // A lens (the bench scene's radtan) and multisampling: the stretches are resolved into their
  // layers and the final pass fetches the turn at each pixel's distorted source position. The
  // eyes turning at 2 rad/s, as above: measured 0.05 DN, 0.006 % of values over 8 DN (through
  // the accumulation, before the final pass took the turn: 0.04 DN, 0.01 %).
  std::string lens_yaml = HeadAndBallScene(16);
  const std::string calibration =
      "{calibration: {width: 1024, height: 768, focal_length_mm: 6.0, pixel_size_um: 4.65, "
      "distortion: {model: radtan, coefficients: [-0.2, 0.1, 0.0005, -0.0003, 0.0]}}, sensor: ";
  for (const std::string eye : {"left: ", "right: "}) {
    const std::size_t at = lens_yaml.find(eye + "{sensor: ");
    ASSERT_NE(at, std::string::npos);
    lens_yaml.replace(at, eye.size() + 9, eye + calibration);
  }
  const scene::Scene lens_world = SceneFrom(lens_yaml);
  ASSERT_EQ(lens_world.FindCamera("left")->model.distortion().model(),
            geometry::DistortionModel::kRadialTangential);
  RendererOptions drawn_msaa = drawn;
  drawn_msaa.msaa_samples = 4;
  RendererOptions turned_msaa = turned;
  turned_msaa.msaa_samples = 4;
  const std::vector<Frame> lens_want = MakeRenderer(lens_world, drawn_msaa)->Render(turning, 3);
  const std::vector<Frame> lens_got = MakeRenderer(lens_world, turned_msaa)->Render(turning, 3);
  for (int i = 0; i < 2; ++i) {
    const Image& a = *lens_got[i].color;
    const Image& b = *lens_want[i].color;
    EXPECT_FALSE(SamePixels(a, b)) << i;
    const auto [mean, over] = compare(a, b, 40);
    EXPECT_LT(mean, 0.25) << i << Keep(a, "lens_turned") << Keep(b, "lens_drawn");
    EXPECT_LT(over, 0.005) << i;
  }
}

// A turning camera's fetches through the turn on the CPU (RendererOptions::turn_blur_on_cpu,
// the default on llvmpipe: the stretches read back) give the final pass's image within a DN:
// the pass weighs each fetch with 8 fractional bits and rounds it, the CPU weighs in float and
// rounds the mean once. A fetch a pixel off, or a homography applied the wrong way round, would
// differ by tens of DN on every edge of the checker ground and the ball. With noise, the same
// deviates: the two differ where the signal rounded differently, by about as much.
TEST(MotionBlurTest, TheTurnFetchedOnTheCpuIsTheFinalPassWithinADn) {
  for (const bool noise : {false, true}) {
    SCOPED_TRACE(noise ? "with noise" : "without noise");
    std::string yaml = HeadAndBallScene(16);
    if (noise) {
      for (std::size_t at = 0; (at = yaml.find("blur_samples: 16}", at)) != std::string::npos;) {
        yaml.replace(at, 17, "blur_samples: 16, read_noise_dn: 2.0, gain_dn_per_e: 0.1}");
        ++at;
      }
    }
    const scene::Scene world = SceneFrom(yaml);
    ASSERT_EQ(world.FindCamera("left")->sensor.read_noise_dn, noise ? 2.0 : 0.0);
    scene::SceneState turning = world.InitialState();
    turning.joint_velocities[2] = 2.0;
    turning.joint_velocities[3] = -2.0;
    RendererOptions options;
    options.noise = noise;
    options.turn_blur_on_cpu = false;
    const std::vector<Frame> pass = MakeRenderer(world, options)->Render(turning, 5);
    options.turn_blur_on_cpu = true;
    const std::vector<Frame> cpu = MakeRenderer(world, options)->Render(turning, 5);
    for (int i = 0; i < 2; ++i) {
      const Image& a = *cpu[i].color;
      const Image& b = *pass[i].color;
      EXPECT_EQ(a.metadata().exposure_samples, b.metadata().exposure_samples) << i;
      EXPECT_GE(a.metadata().exposure_samples, 8) << i;
      ASSERT_EQ(a.size_bytes(), b.size_bytes());
      std::size_t differ = 0;
      int worst = 0;
      int64_t sum = 0;
      for (std::size_t k = 0; k < a.size_bytes(); ++k) {
        const int d = a.data()[k] - b.data()[k];
        differ += d != 0;
        worst = std::max(worst, std::abs(d));
        sum += d;
      }
      std::cout << "eye " << i << ": " << differ << " of " << a.size_bytes()
                << " values differ, by at most " << worst << "\n";
      EXPECT_GT(differ, 0u) << "the same image: the CPU did not fetch the turn";
      EXPECT_LE(worst, noise ? 2 : 1) << Keep(a, "turn_cpu") << " " << Keep(b, "turn_pass");
      EXPECT_LT(static_cast<double>(differ) / a.size_bytes(), 0.05) << differ << " differ";
      EXPECT_LT(std::abs(static_cast<double>(sum) / a.size_bytes()), 0.02) << sum;
    }
  }
}

// The turn's AVX2 loop and its portable one give the same rows to the bit: random stretches,
// homographies of a turn with some perspective, fetches past every edge (clamped), and a width
// that leaves a tail for the portable loop.
TEST(MotionBlurTest, TheTurnsVectorLoopEqualsThePortableOne) {
  const int w = 203, h = 61;
  std::vector<uint8_t> layers(2 * 4 * static_cast<std::size_t>(w) * h);
  uint32_t state = 4242;
  for (uint8_t& b : layers)
    b = static_cast<uint8_t>((state = state * 1664525u + 1013904223u) >> 24);
  gl::CpuTurn turn;
  for (int k = 0; k < 7; ++k) {
    Eigen::Matrix3f m = Eigen::Matrix3f::Identity();
    m(0, 2) = -30.0f + 11.3f * k;  // shifts past the left and the right edge
    m(1, 2) = 0.37f * k - 2.0f;
    m(0, 1) = 0.01f * k;
    m(2, 0) = 1e-4f * (k - 3);  // perspective
    turn.homographies.push_back(m);
    turn.layers.push_back(k % 2);
  }
  turn.stretches = 2;
  std::vector<uint8_t> fast(4 * w), portable(4 * w);
  std::size_t blurred = 0;
  for (int y = 0; y < h; ++y) {
    gl::TurnBlurRow(turn, layers.data(), w, h, y, fast.data());
    gl::TurnBlurRow(turn, layers.data(), w, h, y, portable.data(), /*simd=*/false);
    ASSERT_EQ(fast, portable) << "row " << y;
    for (int x = 0; x < w; ++x) {
      EXPECT_EQ(fast[4 * x + 3], 255);
      blurred += fast[4 * x] != layers[4 * (static_cast<std::size_t>(y) * w + x)];
    }
  }
  EXPECT_GT(blurred, static_cast<std::size_t>(w) * h / 2);  // the mean, not a copy
}

// --- ground truth ----------------------------------------------------------------------------

// A tilted plate and a sphere at about 2 m, seen by a camera with the given calibration.
struct TruthScene {
  Vector3d sphere_centre{1.8, 0.4, 1.1};
  double sphere_radius = 0.2;
  // The plate: a box 0.02 thick, its front face the plane n.p = d.
  Vector3d plate_centre{2.3, -0.35, 1.0};
  double plate_yaw_deg = 35.0;
  double plate_thickness = 0.02;

  std::string Yaml(const std::string& calibration, const Vector3d& target) const {
    char buffer[2048];
    std::snprintf(buffer, sizeof(buffer), R"(
background: [0.6, 0.7, 0.8]
lights: [{type: ambient, intensity: 0.5}, {type: directional, direction: [1, -0.5, -1]}]
ground: {pattern: grid}
objects:
  - {name: ball, kind: sphere, id: 3, radius: %.17g, pose: {position: [%.17g, %.17g, %.17g]}}
  - {name: plate, kind: box, id: 9, size: [%.17g, 1.2, 1.4],
     pose: {position: [%.17g, %.17g, %.17g], rpy_deg: [0, 0, %.17g]}}
cameras:
  - name: cam
    calibration: %s
    look_at: {eye: [0, 0, 1], target: [%.17g, %.17g, %.17g]}
)",
                  sphere_radius, sphere_centre.x(), sphere_centre.y(), sphere_centre.z(),
                  plate_thickness, plate_centre.x(), plate_centre.y(), plate_centre.z(),
                  plate_yaw_deg, calibration.c_str(), target.x(), target.y(), target.z());
    return buffer;
  }
};

// Ray from the world origin of camera `cam` through pixel (u, v), in the world.
struct WorldRay {
  Vector3d origin;
  Vector3d direction;
};

std::optional<WorldRay> PixelRay(const scene::Scene& world, const Frame& frame, int u, int v) {
  const scene::CameraSpec& camera = world.cameras()[0];
  const std::optional<Vector3d> ray = camera.model.Unproject(Vector2d(u, v));
  if (!ray) return std::nullopt;
  const Eigen::Matrix4d X_WC = geometry::FindCameraPose(frame.color->metadata())->matrix();
  return WorldRay{X_WC.block<3, 1>(0, 3), X_WC.block<3, 3>(0, 0) * *ray};
}

// Distance along the ray to the sphere, if it hits.
std::optional<double> HitSphere(const WorldRay& r, const Vector3d& c, double radius) {
  const Vector3d oc = r.origin - c;
  const double b = oc.dot(r.direction);
  const double disc = b * b - (oc.squaredNorm() - radius * radius);
  if (disc < 0) return std::nullopt;
  const double t = -b - std::sqrt(disc);
  return t > 0 ? std::optional<double>(t) : std::nullopt;
}

void CheckTruth(const scene::Scene& world, const TruthScene& t, const std::string& name) {
  RendererOptions options;
  options.truth_depth = true;
  options.truth_ids = true;
  options.truth_objects = true;
  options.msaa_samples = 4;
  const std::vector<Frame> frames = RenderOnce(world, options);
  const Frame& frame = frames[0];
  ASSERT_TRUE(frame.depth && frame.ids);
  ASSERT_EQ(frame.depth->format(), PixelFormat::kFloat32);
  ASSERT_EQ(frame.ids->format(), PixelFormat::kUint32);
  const int w = frame.color->width(), h = frame.color->height();

  const Eigen::Matrix4d X_WC = geometry::FindCameraPose(frame.color->metadata())->matrix();
  const Eigen::Matrix3d R_CW = X_WC.block<3, 3>(0, 0).transpose();
  const Vector3d p_WC = X_WC.block<3, 1>(0, 3);
  const double yaw = t.plate_yaw_deg * std::numbers::pi / 180.0;
  const Vector3d plate_normal(-std::cos(yaw), -std::sin(yaw), 0.0);  // towards the camera
  const Vector3d plate_front = t.plate_centre + 0.5 * t.plate_thickness * plate_normal;

  int64_t sphere_px = 0, plate_px = 0, checked_depth = 0, wrong_id = 0, missed = 0;
  double worst_depth_mm = 0.0;
  int box_x0 = w, box_y0 = h, box_x1 = -1, box_y1 = -1;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      uint32_t id;
      float depth;
      std::memcpy(&id, frame.ids->row(v) + 4 * u, 4);
      std::memcpy(&depth, frame.depth->row(v) + 4 * u, 4);
      const std::optional<WorldRay> ray = PixelRay(world, frame, u, v);
      if (!ray) {
        EXPECT_EQ(id, 0u);
        continue;
      }
      // The pixel's footprint in metres at 2.5 m, for silhouette tolerance: 1.5 px.
      const double focal = world.cameras()[0].model.intrinsics().fx();
      const double slack = 1.5 * 2.5 / focal;
      const std::optional<double> hit_sphere = HitSphere(*ray, t.sphere_centre, t.sphere_radius);
      if (id == 3) {
        ++sphere_px;
        box_x0 = std::min(box_x0, u), box_x1 = std::max(box_x1, u);
        box_y0 = std::min(box_y0, v), box_y1 = std::max(box_y1, v);
        // Every id pixel belongs to the object it names: its ray meets the sphere (grown by
        // the silhouette slack).
        // (Its depth is not compared: the sphere is a tessellated mesh, inside the true
        // sphere by up to a few millimetres between vertices; the plate's face is exact.)
        if (!HitSphere(*ray, t.sphere_centre, t.sphere_radius + slack)) ++wrong_id;
      } else if (id == 9) {
        ++plate_px;
        // The plate's front face: the ray meets the plane within the plate's rectangle.
        const double denom = ray->direction.dot(plate_normal);
        if (denom >= 0) {
          ++wrong_id;
          continue;
        }
        const double s = (plate_front - ray->origin).dot(plate_normal) / denom;
        const Vector3d p_W = ray->origin + s * ray->direction;
        const Vector3d local = p_W - plate_front;
        const bool inside =
            std::abs(local.z()) <= 0.7 - slack &&
            std::abs(local.dot(Vector3d(-plate_normal.y(), plate_normal.x(), 0))) <= 0.6 - slack;
        // (Grown by the plate's thickness too: its side faces show at the edges.)
        const double grown = slack + t.plate_thickness;
        const bool near_inside =
            std::abs(local.z()) <= 0.7 + grown &&
            std::abs(local.dot(Vector3d(-plate_normal.y(), plate_normal.x(), 0))) <= 0.6 + grown;
        if (!near_inside) ++wrong_id;
        // Depth against the plane, away from the plate's edges and the sphere's silhouette.
        if (inside && !HitSphere(*ray, t.sphere_centre, t.sphere_radius + 2 * slack)) {
          const double z = (R_CW * (p_W - p_WC)).z();
          worst_depth_mm = std::max(worst_depth_mm, 1e3 * std::abs(depth - z));
          ++checked_depth;
        }
      } else if (hit_sphere && HitSphere(*ray, t.sphere_centre, t.sphere_radius - slack)) {
        ++missed;  // the sphere is in front of everything else in this scene
      }
    }
  }
  SCOPED_TRACE(name);
  EXPECT_GT(sphere_px, 500);
  EXPECT_GT(checked_depth, 2000);
  EXPECT_EQ(wrong_id, 0) << Keep(*frame.color, name);
  EXPECT_EQ(missed, 0) << Keep(*frame.color, name);
  // The issue's bound: depth within 1 mm at about 2 m.
  constexpr double kMaxDepthErrorMm = 1.0;
  EXPECT_LT(worst_depth_mm, kMaxDepthErrorMm);
  std::printf("[%s] sphere %lld px, plate %lld px, depth checked on %lld px, worst %.4f mm\n",
              name.c_str(), static_cast<long long>(sphere_px), static_cast<long long>(plate_px),
              static_cast<long long>(checked_depth), worst_depth_mm);

  // The objects' truth: the sphere's box is exactly its id pixels' box, and its pose is the
  // scene's.
  ASSERT_EQ(frame.objects.size(), 2u);
  const ObjectTruth& ball = frame.objects[0];
  EXPECT_EQ(ball.id, 3u);
  EXPECT_EQ(ball.name, "ball");
  EXPECT_EQ(ball.pixels, sphere_px);
  EXPECT_EQ(ball.x_min, box_x0);
  EXPECT_EQ(ball.y_min, box_y0);
  EXPECT_EQ(ball.x_max, box_x1);
  EXPECT_EQ(ball.y_max, box_y1);
  const Vector3d p_WO = ball.X_WO.block<3, 1>(0, 3);
  EXPECT_TRUE(p_WO.isApprox(t.sphere_centre, 1e-12));
  const Eigen::Matrix4d X_CO = X_WC.inverse() * ball.X_WO;
  EXPECT_TRUE(ball.X_CO.isApprox(X_CO, 1e-12));
  // Its centre projects (through the lens) inside its box.
  const std::optional<Vector2d> centre = world.cameras()[0].model.Project(X_CO.block<3, 1>(0, 3));
  ASSERT_TRUE(centre.has_value());
  EXPECT_GE(centre->x(), ball.x_min);
  EXPECT_LE(centre->x(), ball.x_max);
  EXPECT_GE(centre->y(), ball.y_min);
  EXPECT_LE(centre->y(), ball.y_max);
  EXPECT_EQ(frame.objects[1].pixels, plate_px);
}

TEST(TruthTest, DepthAndIdsAgreeWithTheGeometryThroughAStrongRadTanLens) {
  const TruthScene t;
  const scene::Scene world = SceneFrom(t.Yaml(
      "{width: 800, height: 600, fx: 620, fy: 618, cx: 402.5, cy: 297.25, distortion: {model: "
      "radtan, coefficients: [-0.32, 0.11, 0.0009, -0.0012, -0.015]}}",
      Vector3d(2.0, 0.0, 1.05)));
  CheckTruth(world, t, "radtan");
}

TEST(TruthTest, DepthAndIdsAgreeWithTheGeometryThroughA190DegreeFisheye) {
  // The objects seen at 40 to 80 degrees off the axis of a 190-degree lens that looks up
  // and sideways, so that several cube faces carry them.
  const TruthScene t;
  const scene::Scene world = SceneFrom(t.Yaml(
      "{width: 800, height: 800, fx: 240, fy: 240, distortion: {model: fisheye, coefficients: "
      "[0.01, -0.004, 0.0005, -0.0001]}}",
      Vector3d(1.0, 1.5, 2.2)));
  const geometry::LensMap lens = geometry::MakeLensMap(world.cameras()[0].model);
  ASSERT_EQ(lens.kind, geometry::LensMap::Kind::kCube);
  ASSERT_GT(lens.max_angle, 95.0 * std::numbers::pi / 180.0);
  CheckTruth(world, t, "fisheye190");
}

TEST(TruthTest, DistortionOffRendersThePinholeAndSaysSo) {
  const TruthScene t;
  const scene::Scene world = SceneFrom(t.Yaml(
      "{width: 320, height: 240, fx: 250, fy: 250, distortion: {model: radtan, coefficients: "
      "[-0.3, 0.1, 0, 0, 0]}}",
      Vector3d(2.0, 0.0, 1.05)));
  RendererOptions pinhole;
  pinhole.distortion = false;
  const Frame distorted = RenderOnce(world)[0];
  const Frame plain = RenderOnce(world, pinhole)[0];
  EXPECT_EQ(testing_helpers::DistortionName(distorted.color->metadata()), "radtan");
  EXPECT_EQ(testing_helpers::DistortionName(plain.color->metadata()), "none");
  EXPECT_TRUE(testing_helpers::Coefficients(plain.color->metadata()).empty());
  EXPECT_FALSE(SamePixels(*distorted.color, *plain.color));
  EXPECT_FALSE(distorted.depth);  // not asked for
  EXPECT_TRUE(distorted.objects.empty());
}

// --- switching effects -------------------------------------------------------------------

// Renderer::SetEffects keeps the context and everything uploaded, and remakes only the
// cameras' targets: after a switch the frames are bit for bit those of a renderer made with
// the new options, for every combination, both ways, and with the head turning and the ball
// moving (blur), the lens (distortion) and the sensor (noise) all in play.
TEST(SetEffectsTest, SwitchedEffectsGiveTheFramesOfARendererMadeWithThem) {
  const std::string camera =
      "{calibration: {width: 320, height: 240, fx: 250, fy: 250, distortion: {model: radtan, "
      "coefficients: [-0.25, 0.08, 0.001, -0.0005, 0]}}, sensor: {exposure: 0.01, "
      "blur_samples: 8, read_noise_dn: 2.0, gain_dn_per_e: 0.1, seed: 3}}";
  const scene::Scene world = SceneFrom(R"(
background: [0.6, 0.7, 0.8]
lights: [{type: ambient, intensity: 0.4}, {type: directional, direction: [1, 0, -1]}]
ground: {pattern: checker, cell: 0.25}
objects:
  - {name: ball, kind: sphere, radius: 0.2, pose: {position: [2, 0.3, 1.2]}, color: [0.9, 0.2, 0.1, 1],
     motion: {type: constant_velocity, linear: [0, -2, 0]}}
robot:
  head: ../robots/popeye.yaml
  pose: {position: [0, 0, 1.2]}
  cameras:
    left: )" + camera +
                                       "\n    right: " + camera + "\n");
  scene::SceneState state = world.InitialState();
  state.time = 0.1;
  state.joint_velocities[0] = 2.0;

  std::unique_ptr<Renderer> switched = MakeRenderer(world);
  int64_t frame = 0;
  std::vector<std::vector<uint8_t>> seen;  // the left images, in the order switched to
  // Every combination; switches of the noise or the blur alone, which keep the targets (blur
  // on again, and on for a target made without it).
  for (const int bits : {0, 2, 7, 5, 1, 3, 6, 4, 7, 2, 0, 2, 6, 2, 6}) {
    RendererOptions options;
    options.distortion = (bits & 1) != 0;
    options.noise = (bits & 2) != 0;
    options.motion_blur = (bits & 4) != 0;
    SCOPED_TRACE("distortion " + std::to_string(options.distortion) + ", noise " +
                 std::to_string(options.noise) + ", blur " + std::to_string(options.motion_blur));
    switched->SetEffects(EffectSwitches::Of(options));
    ++frame;
    const std::vector<Frame> got = switched->Render(state, frame);
    const std::vector<Frame> made = RenderOnce(world, options, &state, frame);
    ASSERT_EQ(got.size(), 2u);
    for (int i = 0; i < 2; ++i) {
      EXPECT_TRUE(SamePixels(*got[i].color, *made[i].color))
          << i << ": " << Keep(*got[i].color, "switched");
      EXPECT_EQ(testing_helpers::DistortionName(got[i].color->metadata()),
                options.distortion ? "radtan" : "none");
      EXPECT_EQ(got[i].color->metadata().exposure_samples,
                made[i].color->metadata().exposure_samples);
      EXPECT_EQ(got[i].color->metadata().exposure_samples > 1, options.motion_blur) << i;
    }
    const uint8_t* left = got[0].color->data();
    seen.emplace_back(left, left + got[0].color->size_bytes());
  }
  for (int a = 0; a < 8; ++a) {  // the first eight are the eight combinations
    for (int b = 0; b < a; ++b) EXPECT_NE(seen[a], seen[b]) << "switches " << b << " and " << a;
  }

  // Not while a state is in flight: its pixels were drawn with the effects it was submitted with.
  switched->Submit(state, ++frame);
  EXPECT_THROW(switched->SetEffects({false, false, false, true, true}), Error);
  EXPECT_EQ(switched->Retrieve()[0].color->metadata().frame_index, frame);
  switched->SetEffects({false, false, false, true, true});
  EXPECT_EQ(testing_helpers::DistortionName(switched->Render(state, ++frame)[0].color->metadata()),
            "none");
}

// The lens's light and the sensor's colour switch as the others: a camera with vignetting,
// depth of field (which draws depth) and a Bayer filter, and one whose EMVA sensor exposes the
// mosaic with the colour on and the RGB image without, give after each switch the frames (and
// the mosaic, or none) of a renderer made with the switches, noise and distortion on.
TEST(SetEffectsTest, OpticsAndColourSwitchAsARendererMadeWithThem) {
  const scene::Scene world = SceneFrom(R"(
background: [0.6, 0.7, 0.8]
lights: [{type: ambient, intensity: 0.5}, {type: directional, direction: [1, 0, -1]}]
ground: {pattern: checker, cell: 0.25, color: [0.9, 0.5, 0.2], color2: [0.1, 0.3, 0.8]}
cameras:
  - name: real
    calibration: {width: 96, height: 72, fx: 70, fy: 70,
                  distortion: {model: radtan, coefficients: [-0.2, 0.05, 0, 0, 0]}}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {read_noise_dn: 2, gain_dn_per_e: 0.2, seed: 3,
             color: {cfa: rggb, white_balance: {red: 1.3, blue: 1.6}, tone_curve: srgb}}
    lens: {vignetting: cos4, f_number: 1.4, focal_length_mm: 6, focus_distance: 1, max_coc_px: 4}
  - name: emva
    calibration: {width: 64, height: 48, fx: 50, fy: 50}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {exposure_ms: 8, seed: 5, emva: {preset: imx174}, color: {cfa: bggr}}
    lens: {vignetting: cos4}
)");
  const scene::SceneState state = world.InitialState();
  std::unique_ptr<Renderer> switched = MakeRenderer(world);
  int64_t frame = 0;
  std::vector<std::vector<uint8_t>> seen;
  for (const int bits : {0, 1, 3, 2, 0, 3}) {
    RendererOptions options;
    options.optics = (bits & 1) != 0;
    options.color = (bits & 2) != 0;
    SCOPED_TRACE("optics " + std::to_string(options.optics) + ", color " +
                 std::to_string(options.color));
    switched->SetEffects(EffectSwitches::Of(options));
    ++frame;
    const std::vector<Frame> got = switched->Render(state, frame);
    const std::vector<Frame> made = RenderOnce(world, options, &state, frame);
    ASSERT_EQ(got.size(), 2u);
    for (int i = 0; i < 2; ++i) {
      EXPECT_TRUE(SamePixels(*got[i].color, *made[i].color))
          << i << ": " << Keep(*got[i].color, "switched");
      ASSERT_EQ(got[i].raw != nullptr, options.color) << i;
      if (options.color) {
        EXPECT_TRUE(SamePixels(*got[i].raw, *made[i].raw)) << i;
      }
    }
    const uint8_t* pixels = got[0].color->data();
    seen.emplace_back(pixels, pixels + got[0].color->size_bytes());
  }
  for (int a = 0; a < 4; ++a) {  // the first four are the four combinations
    for (int b = 0; b < a; ++b) EXPECT_NE(seen[a], seen[b]) << "switches " << b << " and " << a;
  }
}

}  // namespace
}  // namespace saccade::render
