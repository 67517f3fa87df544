// Commanded exposure, gain and focus (scene/camera_controls.h) in the renderer: brightness
// without a sensor, the EMVA sensor's photons and gain, motion blur over the commanded
// exposure, the frame's metadata, and bad commands.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

// 20 log10(2): a gain of 2.
const double kDoubleDb = 20.0 * std::log10(2.0);

scene::Scene SceneFrom(const std::string& yaml) {
  return scene::Scene::FromYamlString(yaml, "camera_controls_test.yaml",
                                      std::filesystem::temp_directory_path());
}

// Two cameras that see only the sky, 100 DN in every channel; `sensor` is the first one's
// sensor (the second's exposure is 0: an instant, nominally kNominalExposureS).
scene::Scene SkyScene(const std::string& sensor) {
  return SceneFrom(R"(
background: [0.39215686274509803, 0.39215686274509803, 0.39215686274509803]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
cameras:
  - name: sky
    calibration: {width: 64, height: 48, fx: 50, fy: 50}
    pose: {position: [0, 0, 1]}
    sensor: )" + sensor +
                   R"(
  - name: instant
    calibration: {width: 64, height: 48, fx: 50, fy: 50}
    pose: {position: [0, 0, 1]}
)");
}

std::vector<Frame> RenderWith(const scene::Scene& world, const scene::SceneState& state,
                              int64_t frame = 0, const RendererOptions& options = {}) {
  return MakeRenderer(world, options)->Render(state, frame);
}

bool SamePixels(const Image& a, const Image& b) {
  return a.width() == b.width() && a.height() == b.height() &&
         std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

// Every value of the image equals `value`.
bool Uniform(const Image& image, int value) {
  for (std::size_t i = 0; i < image.size_bytes(); ++i) {
    if (image.data()[i] != value) return false;
  }
  return true;
}

double Mean(const Image& image) {
  double sum = 0.0;
  for (std::size_t i = 0; i < image.size_bytes(); ++i) sum += image.data()[i];
  return sum / static_cast<double>(image.size_bytes());
}

TEST(CameraControlsTest, WithoutASensorExposureAndGainScaleTheBrightness) {
  const scene::Scene world = SkyScene("{exposure: 0.01}");
  scene::SceneState state = world.InitialState();
  const std::vector<Frame> plain = RenderWith(world, state);
  ASSERT_TRUE(Uniform(*plain[0].color, 100));
  EXPECT_DOUBLE_EQ(plain[0].color->metadata().exposure_s, 0.01);
  EXPECT_DOUBLE_EQ(plain[0].color->metadata().gain_db, 0.0);
  EXPECT_DOUBLE_EQ(plain[0].color->metadata().focus_m, 0.0);
  EXPECT_DOUBLE_EQ(plain[1].color->metadata().exposure_s, 0.0);  // an instant

  struct Case {
    scene::CameraControls controls;
    int expected;
  };
  const std::vector<Case> cases = {
      {{0.02, std::nullopt, std::nullopt}, 200},       // twice the exposure
      {{0.005, std::nullopt, std::nullopt}, 50},       // half
      {{std::nullopt, kDoubleDb, std::nullopt}, 200},  // a gain of 2
      {{0.0025, kDoubleDb, std::nullopt}, 50},         // a quarter, twice
      {{0.04, std::nullopt, std::nullopt}, 255},       // 400: clipped (saturated)
      {{std::nullopt, std::nullopt, 1.5}, 100},        // focus alone: the same brightness
  };
  for (const Case& c : cases) {
    state.camera_controls = {{"sky", c.controls}, {"instant", c.controls}};
    const std::vector<Frame> frames = RenderWith(world, state);
    EXPECT_TRUE(Uniform(*frames[0].color, c.expected)) << Mean(*frames[0].color);
    // The camera without an exposure stands for kNominalExposureS (10 ms), as the first.
    EXPECT_TRUE(Uniform(*frames[1].color, c.expected)) << Mean(*frames[1].color);
    const ImageMetadata& meta = frames[0].color->metadata();
    EXPECT_DOUBLE_EQ(meta.exposure_s, c.controls.exposure_s.value_or(0.01));
    EXPECT_DOUBLE_EQ(meta.gain_db, c.controls.gain_db.value_or(0.0));
    EXPECT_DOUBLE_EQ(meta.focus_m, c.controls.focus_m.value_or(0.0));
  }
}

TEST(CameraControlsTest, NoCommandOrTheFilesOwnValuesRenderTheSameBits) {
  // Legacy noise on: the same noise draws whatever the (neutral) commands.
  const scene::Scene world = SkyScene("{exposure: 0.01, read_noise_dn: 3, gain_dn_per_e: 0.2}");
  scene::SceneState state = world.InitialState();
  const std::vector<Frame> plain = RenderWith(world, state, 4);
  ASSERT_FALSE(Uniform(*plain[0].color, 100));  // noisy
  state.camera_controls["sky"] = scene::CameraControls{};
  EXPECT_TRUE(SamePixels(*plain[0].color, *RenderWith(world, state, 4)[0].color));
  state.camera_controls["sky"] = scene::CameraControls{0.01, 0.0, std::nullopt};
  EXPECT_TRUE(SamePixels(*plain[0].color, *RenderWith(world, state, 4)[0].color));
}

TEST(CameraControlsTest, TheEmvaSensorCollectsPhotonsOverTheCommandedExposureTimesTheGain) {
  // 128 DN of sky through an 8-bit sensor of K = 1, eta = 1 at 10 ms: 102.4 electrons.
  const scene::Scene world = SceneFrom(R"(
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
)");
  const auto mean_and_variance = [&](const scene::CameraControls& controls) {
    scene::SceneState state = world.InitialState();
    state.camera_controls["flat"] = controls;
    std::unique_ptr<Renderer> renderer = MakeRenderer(world, {});
    const Image a = *renderer->Render(state, 1)[0].color;
    const Image b = *renderer->Render(state, 2)[0].color;
    double sum = 0.0, diff = 0.0, diff2 = 0.0;
    const double n = static_cast<double>(a.size_bytes());
    for (std::size_t i = 0; i < a.size_bytes(); ++i) {
      sum += a.data()[i];
      const double d = static_cast<double>(a.data()[i]) - b.data()[i];
      diff += d;
      diff2 += d * d;
    }
    return std::pair{sum / n, (diff2 / n - (diff / n) * (diff / n)) / 2.0};
  };
  // Standard errors at 57600 values: ~0.05 DN of the mean, ~0.6 % of the variance.
  constexpr double kMeanToleranceDn = 0.3;
  constexpr double kVarianceTolerance = 0.04;
  // 15 ms: 153.6 electrons = 153.6 DN; variance shot + dark + rounding.
  const auto [mean15, var15] = mean_and_variance({0.015, std::nullopt, std::nullopt});
  EXPECT_NEAR(mean15, 153.6, kMeanToleranceDn);
  EXPECT_NEAR(var15 / (153.6 + 4.0 + 1.0 / 12.0), 1.0, kVarianceTolerance) << var15;
  // 10 ms with a gain of 1.5: K 1.5, so 153.6 DN again but 1.5^2 times the electrons' noise.
  const double gain15_db = 20.0 * std::log10(1.5);
  const auto [mean_g, var_g] = mean_and_variance({std::nullopt, gain15_db, std::nullopt});
  EXPECT_NEAR(mean_g, 153.6, kMeanToleranceDn);
  EXPECT_NEAR(var_g / (2.25 * (102.4 + 4.0) + 1.0 / 12.0), 1.0, kVarianceTolerance) << var_g;
}

std::string MovingBox(double exposure) {
  return R"(
background: [0, 0, 0]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
objects:
  - name: box
    kind: box
    size: [0.05, 0.4, 0.4]
    color: [1, 1, 1, 1]
    motion: {type: constant_velocity, linear: [0, 3, 0]}
    pose: {position: [2, 0, 1]}
cameras:
  - name: cam
    calibration: {width: 160, height: 120, fx: 200, fy: 200}
    look_at: {eye: [0, 0, 1], target: [2, 0, 1]}
    sensor: {exposure: )" +
         std::to_string(exposure) + ", blur_samples: 16}\n";
}

TEST(CameraControlsTest, MotionBlurFollowsTheCommandedExposure) {
  // A box at 3 m/s, 2 m away, f = 200 px: 6 px over 20 ms, 3 px over 10 ms. Commanding 10 ms
  // (and a gain of 2, to keep the brightness of 20 ms) renders what a file's 10 ms renders.
  const scene::Scene file20 = SceneFrom(MovingBox(0.02));
  const scene::Scene file10 = SceneFrom(MovingBox(0.01));
  scene::SceneState state = file20.InitialState();
  const std::vector<Frame> at20 = RenderWith(file20, state);
  state.camera_controls["cam"] = scene::CameraControls{0.01, kDoubleDb, std::nullopt};
  const std::vector<Frame> commanded = RenderWith(file20, state);
  const std::vector<Frame> at10 = RenderWith(file10, file10.InitialState());
  EXPECT_TRUE(SamePixels(*commanded[0].color, *at10[0].color));
  EXPECT_EQ(commanded[0].color->metadata().exposure_samples,
            at10[0].color->metadata().exposure_samples);
  EXPECT_GT(at20[0].color->metadata().exposure_samples, at10[0].color->metadata().exposure_samples);
  EXPECT_FALSE(SamePixels(*commanded[0].color, *at20[0].color));
}

TEST(CameraControlsTest, BadCommandsAreErrorsNamingTheCameraTheControlAndTheValue) {
  const scene::Scene world = SkyScene("{exposure: 0.01}");
  std::unique_ptr<Renderer> renderer = MakeRenderer(world, {});
  const auto message = [&](const std::string& camera, const scene::CameraControls& controls) {
    scene::SceneState state = world.InitialState();
    state.camera_controls[camera] = controls;
    try {
      renderer->Render(state, 0);
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("sky", {0.0, std::nullopt, std::nullopt}),
            "Renderer::Submit: camera 'sky': exposure_s must be seconds in (0, 1], got 0");
  EXPECT_EQ(message("sky", {1.5, std::nullopt, std::nullopt}),
            "Renderer::Submit: camera 'sky': exposure_s must be seconds in (0, 1], got 1.5");
  EXPECT_EQ(message("sky", {std::nullopt, -3.0, std::nullopt}),
            "Renderer::Submit: camera 'sky': gain_db must be dB in [0, 48], got -3");
  EXPECT_EQ(message("sky", {std::nullopt, std::nullopt, 0.0}),
            "Renderer::Submit: camera 'sky': focus_m must be a distance in metres > 0, got 0");
  EXPECT_EQ(message("sly", {0.01, std::nullopt, std::nullopt}),
            "Renderer::Submit: camera controls for 'sly', a camera the scene does not have (it "
            "has: sky, instant)");
  // The renderer still works after a refused state.
  EXPECT_TRUE(Uniform(*renderer->Render(world.InitialState(), 1)[0].color, 100));
}

}  // namespace
}  // namespace saccade::render
