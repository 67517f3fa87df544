// Camera controls in pipelines: sim.cameras applies commanded exposure, gain and focus with a
// camera's latency, camera.auto_exposure holds a target brightness through a light change with
// the real renderer, camera.accommodation focuses at the vergence distance; bad values.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/accommodation_component.h"
#include "saccade/components/auto_exposure_component.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/head/fixation.h"
#include "saccade/head/head_model.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "scratch_dir.h"

namespace saccade::components {
namespace {

using nlohmann::json;
const std::string kSource = SACCADE_SOURCE_DIR;

std::string WriteScene(const std::string& name, const std::string& yaml) {
  const std::string path = (testing_helpers::ScratchDir() / name).string();
  std::ofstream(path) << yaml;
  return path;
}

// A camera before a light grey wall (0.9 of full white under an ambient light of 1: 0.9 of
// full scale at the file's 10 ms). A dark grey card (0.1: a ninth of the wall's brightness)
// drops in front of the camera at 1.0 s and leaves at 2.2 s: to the camera, the light dimmed
// to a ninth and came back.
std::string LightChangeScene() {
  return WriteScene("light_change.yaml", R"(
background: [0, 0, 0]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
objects:
  - name: wall
    kind: box
    size: [0.1, 8, 8]
    color: [0.9, 0.9, 0.9, 1]
    pose: {position: [4, 0, 1]}
  - name: card
    kind: box
    size: [0.05, 4, 4]
    color: [0.1, 0.1, 0.1, 1]
    motion:
      type: waypoints
      waypoints:
        - {time: 0.99, position: [1, 0, 10]}
        - {time: 1.0, position: [1, 0, 1]}
        - {time: 2.19, position: [1, 0, 1]}
        - {time: 2.2, position: [1, 0, 10]}
cameras:
  - name: eye
    calibration: {width: 160, height: 120, fx: 120, fy: 120}
    look_at: {eye: [0, 0, 1], target: [4, 0, 1]}
    sensor: {exposure: 0.01, blur_samples: 1, read_noise_dn: 1, seed: 3}
)");
}

struct Shot {
  double brightness = 0.0;
  double exposure_s = 0.0;
  double gain_db = 0.0;
  double focus_m = 0.0;
  std::optional<CameraCommand> command;  // what auto exposure sent in this step
};

// Runs `yaml` (a pipeline whose sim.cameras is `cameras` and whose controller's output is
// `controller.controls`) and records the first camera's frames.
std::vector<Shot> RunAndRecord(const std::string& yaml, const std::string& camera) {
  RegisterComponents();
  runtime::Pipeline pipeline =
      runtime::Pipeline::Build(runtime::ParsePipeline(yaml, "camera_controls_test"));
  std::vector<Shot> frames;
  std::optional<CameraCommand> command;
  for (const auto& c : pipeline.components()) {
    for (const auto& o : c->outputs()) {
      if (auto* i = dynamic_cast<runtime::Output<runtime::ImageMessage>*>(o.get())) {
        i->signal().Connect([&](const runtime::ImageMessage& m) {
          if (m.image->metadata().camera != camera) return;
          const ImageMetadata& meta = m.image->metadata();
          frames.push_back({AutoExposureComponent::MeasureBrightness(*m.image, 4, 0.0),
                            meta.exposure_s, meta.gain_db, meta.focus_m, std::nullopt});
        });
      } else if (auto* s = dynamic_cast<runtime::Output<CameraControlsMessage>*>(o.get())) {
        s->signal().Connect([&](const CameraControlsMessage& m) {
          for (const CameraCommand& c : m.commands) {
            if (c.camera == camera || c.camera == "all") command = c;
          }
        });
      }
    }
  }
  runtime::RunOptions options;
  options.after_step = [&](const runtime::StepContext&) {
    if (!frames.empty()) frames.back().command = command;
    command.reset();
  };
  runtime::RunPipeline(pipeline, options);
  return frames;
}

// Settled: within this fraction of the target. Read noise of 1 DN and the metering's
// subsampling move the measured brightness by well under 0.5 %; the deadband (2 % in log)
// lets it rest up to 2 % off.
constexpr double kSettleTolerance = 0.05;
// Frames after a change by which the loop must have settled: the command's log error halves
// each frame (damping 0.5), from ln(9) ~ 2.2 to ln(1.05) ~ 0.05 in 6 frames, and the frames
// see it two frames later: 8 (measured: 5 from the start, 7 after the dimming).
constexpr int kMaxSettleFrames = 8;
// After the light returns the sensor saturates (every pixel at 255): a saturated frame only
// bounds the ideal (by ln(1 / 0.45) ~ 0.8 a frame), so the loop needs a few frames more to get
// off the clip (measured: 11).
constexpr int kMaxSettleFramesFromSaturation = 12;

TEST(AutoExposureTest, SettlesAfterTheLightDimsAndReturnsWithoutOscillating) {
  const std::string pipeline = R"(
clock: {mode: simulated, step: 0.04, steps: 90}
threads: 1
components:
  - name: cameras
    type: sim.cameras
    params: {scene: )" + LightChangeScene() +
                               R"(, cameras: [eye]}
    inputs: {controls: {from: exposure.controls, delay: 1}}
  - name: exposure
    type: camera.auto_exposure
    params: {target: 0.45, max_exposure_s: 0.02, max_gain_db: 24, damping: 0.5}
    inputs: {image: cameras.eye}
)";
  const std::vector<Shot> frames = RunAndRecord(pipeline, "eye");
  ASSERT_EQ(frames.size(), 90u);
  constexpr double kTarget = 0.45;
  // The latency: a command sent in step s applies from frame s + 2 (sim.cameras takes it in
  // step s + 1 and the exposure under way then is not changed).
  std::optional<CameraCommand> in_force;
  for (std::size_t s = 0; s + 2 < frames.size(); ++s) {
    if (frames[s].command) in_force = frames[s].command;
    if (!in_force) {
      EXPECT_DOUBLE_EQ(frames[s + 2].exposure_s, 0.01) << s;
      continue;
    }
    EXPECT_DOUBLE_EQ(frames[s + 2].exposure_s, *in_force->exposure_s) << s;
    EXPECT_DOUBLE_EQ(frames[s + 2].gain_db, *in_force->gain_db) << s;
  }
  // Three phases: the wall from the start, the card (1.0 s: frame 25), the wall (2.2 s: 55).
  struct Phase {
    int begin, end, max_settle;
  };
  const std::vector<Phase> phases = {{0, 25, kMaxSettleFrames},
                                     {25, 55, kMaxSettleFrames},
                                     {55, 90, kMaxSettleFramesFromSaturation}};
  std::string trace;
  for (std::size_t s = 0; s < frames.size(); ++s) {
    trace += fmt::format("{}: {:.3f} ({:.2f} ms, {:.1f} dB)\n", s, frames[s].brightness,
                         frames[s].exposure_s * 1e3, frames[s].gain_db);
  }
  for (const auto& [begin, end, max_settle] : phases) {
    // Settled: every frame from `settled` to the phase's end within the tolerance.
    int settled = end;
    while (settled > begin &&
           std::abs(frames[settled - 1].brightness / kTarget - 1.0) <= kSettleTolerance) {
      --settled;
    }
    EXPECT_LE(settled - begin, max_settle) << "phase from frame " << begin << "\n" << trace;
    // No oscillation: outside the tolerance band, the brightness stays on one side of the
    // target (it approaches from where the change left it, never overshoots to the other).
    int crossings = 0, side = 0;
    for (int s = begin; s < end; ++s) {
      const double error = frames[s].brightness / kTarget - 1.0;
      if (std::abs(error) <= kSettleTolerance) continue;
      const int now = error > 0 ? 1 : -1;
      if (side != 0 && now != side) ++crossings;
      side = now;
    }
    EXPECT_EQ(crossings, 0) << "phase from frame " << begin << "\n" << trace;
    std::printf("phase from frame %d: settled within %d frames\n", begin, settled - begin);
  }
  // Under the card (a ninth of the light) the exposure reached its maximum and the gain made
  // up the rest: 0.45 / (0.1 x 100 ms-equivalent) -> 20 ms and ~7 dB.
  EXPECT_DOUBLE_EQ(frames[50].exposure_s, 0.02);
  EXPECT_GT(frames[50].gain_db, 5.0);
  // Back on the wall: the gain returns to 0, the exposure to ~5 ms.
  EXPECT_DOUBLE_EQ(frames[89].gain_db, 0.0);
  EXPECT_NEAR(frames[89].exposure_s, 0.01 * kTarget / 0.9, 0.01 * kTarget / 0.9 * 0.05);
}

std::unique_ptr<runtime::Component> Make(const std::string& type, const json& params,
                                         const std::string& name = "ctl") {
  RegisterComponents();
  std::unique_ptr<runtime::Component> c = runtime::ComponentRegistry::Global().Create(type);
  c->Initialise(name, 1, {}, nullptr);
  c->Configure(params);
  return c;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

TEST(AutoExposureTest, BadParametersNameTheComponentTheParameterAndTheValue) {
  // The pipeline adds the file, the line and "component 'name' (type): " (pipeline.cc).
  EXPECT_EQ(ErrorOf([] {
              Make("camera.auto_exposure", {{"target", 1.5}});
            }),
            "parameter 'target': expected a number in [0.01, 0.99], got 1.5");
  const std::string gain = ErrorOf([] { Make("camera.auto_exposure", {{"max_gain_db", -6}}); });
  EXPECT_NE(gain.find("max_gain_db"), std::string::npos) << gain;
  EXPECT_NE(gain.find("-6"), std::string::npos) << gain;
  const std::string exposure = ErrorOf([] {
    Make("camera.auto_exposure", {{"max_exposure_s", 0.0}});
  });
  EXPECT_NE(exposure.find("max_exposure_s"), std::string::npos) << exposure;
  EXPECT_EQ(ErrorOf([] {
              Make("camera.auto_exposure", {{"min_exposure_s", 0.05}, {"max_exposure_s", 0.01}});
            }),
            "parameter 'min_exposure_s': expected at most max_exposure_s (0.01 s), got "
            "0.05 s");
  EXPECT_EQ(ErrorOf([] {
              Make("camera.accommodation", {{"min_focus_m", 5}, {"max_focus_m", 1}});
            }),
            "parameter 'min_focus_m': expected at most max_focus_m (1 m), got 5 m");
}

TEST(SimCamerasControlsTest, BadCommandsNameTheComponentTheCameraAndTheValue) {
  const std::string scene = LightChangeScene();
  const auto command = [&](const CameraCommand& c) {
    return ErrorOf([&] {
      std::unique_ptr<runtime::Component> cameras =
          Make("sim.cameras", {{"scene", scene}, {"cameras", {"eye"}}}, "cams");
      auto* input =
          dynamic_cast<runtime::Input<CameraControlsMessage>*>(cameras->FindInput("controls"));
      ASSERT_NE(input, nullptr);
      cameras->Start();
      input->Deliver(CameraControlsMessage{0.0, {c}});
      runtime::StepContext context;
      cameras->Step(context);
    });
  };
  EXPECT_EQ(command({"eye", 0.0, std::nullopt, std::nullopt}),
            "cams: input 'controls': camera 'eye': exposure_s must be seconds in (0, 1], got 0");
  EXPECT_EQ(command({"eye", 2.0, std::nullopt, std::nullopt}),
            "cams: input 'controls': camera 'eye': exposure_s must be seconds in (0, 1], got 2");
  EXPECT_EQ(command({"eye", std::nullopt, -6.0, std::nullopt}),
            "cams: input 'controls': camera 'eye': gain_db must be dB in [0, 48], got -6");
  EXPECT_EQ(command({"all", std::nullopt, 50.0, std::nullopt}),
            "cams: input 'controls': camera 'all': gain_db must be dB in [0, 48], got 50");
  EXPECT_EQ(command({"nose", 0.01, std::nullopt, std::nullopt}),
            "cams: input 'controls': no camera 'nose' in the scene (it has: eye; or \"all\")");
  EXPECT_EQ(command({"eye", 0.01, 6.0, 2.0}), "no error");
}

TEST(CameraControlsMessageTest, RoundTripsThroughJsonWithAbsentValuesAsNull) {
  using Traits = runtime::MessageTraits<CameraControlsMessage>;
  const CameraControlsMessage m{1.5, {{"left", 0.004, std::nullopt, 2.0}, {"all", {}, 6.0, {}}}};
  const json j = Traits::ToJson(m);
  EXPECT_EQ(j.dump(),
            R"({"commands":[{"camera":"left","exposure_s":0.004,"focus_m":2.0,"gain_db":null},)"
            R"({"camera":"all","exposure_s":null,"focus_m":null,"gain_db":6.0}],"time":1.5})");
  const CameraControlsMessage back = Traits::FromJson(
      json::parse(R"({"time": 2, "commands": [{"camera": "right", "gain_db": 3}]})"));
  ASSERT_EQ(back.commands.size(), 1u);
  EXPECT_EQ(back.commands[0].camera, "right");
  EXPECT_FALSE(back.commands[0].exposure_s.has_value());
  EXPECT_EQ(back.commands[0].gain_db, 3.0);
  EXPECT_EQ(ErrorOf([] {
              Traits::FromJson(json::parse(R"({"time": 0, "commands": [{"gain_db": 3}]})"));
            }),
            "camera.controls.commands[0]: missing field 'camera'");
}

// The eye poses of `head` fixating p_W.
std::array<geometry::Pose, 2> Fixating(const head::HeadModel& head, const Eigen::Vector3d& p_W) {
  const head::FixationResult result = head::SolveFixation(head, p_W);
  EXPECT_TRUE(result.reachable()) << result.message;
  std::vector<geometry::Pose> X_WL;
  head.ForwardKinematics(result.joints, &X_WL);
  return {head.CameraPose(0, X_WL), head.CameraPose(1, X_WL)};
}

std::shared_ptr<const Image> EyeImage(const std::string& camera, const geometry::Pose& X_WC) {
  auto image = std::make_shared<Image>(4, 4, PixelFormat::kRgb8);
  image->metadata().camera = camera;
  geometry::SetCameraPose(image->metadata(), X_WC);
  return image;
}

// The commanded focus equals the distance to the fixated point within this fraction (the
// issue's bound; IK fixates to 1e-9 rad, so the error is far smaller).
constexpr double kFocusTolerance = 0.01;

TEST(AccommodationTest, FocusesEachEyeAtTheDistanceItVergesTo) {
  // POPEYE's legacy description and its URDF: the component reads only the images' poses.
  for (const std::string file : {"robots/popeye.yaml", "robots/popeye_urdf.yaml"}) {
    const head::HeadModel head = head::HeadModel::FromFile(kSource + "/" + file);
    std::unique_ptr<runtime::Component> c = Make("camera.accommodation", json::object());
    auto& left = dynamic_cast<runtime::Input<runtime::ImageMessage>&>(*c->FindInput("left"));
    auto& right = dynamic_cast<runtime::Input<runtime::ImageMessage>&>(*c->FindInput("right"));
    auto* output = dynamic_cast<runtime::Output<CameraControlsMessage>*>(c->FindOutput("controls"));
    ASSERT_NE(output, nullptr);
    std::optional<CameraControlsMessage> sent;
    output->signal().Connect([&](const CameraControlsMessage& m) { sent = m; });
    const std::array<geometry::Pose, 2> home = head.CameraPoses(head.Home());
    // Ahead of the head, at 0.4 to 4 m, a little off the mid-axis.
    const Eigen::Vector3d mid = 0.5 * (home[0].translation() + home[1].translation());
    const Eigen::Vector3d ahead = (home[0].linear().col(2) + home[1].linear().col(2)).normalized();
    const Eigen::Vector3d up = -home[0].linear().col(1);
    for (const double d : {0.4, 1.0, 2.0, 4.0}) {
      const Eigen::Vector3d p_W = mid + d * ahead + 0.05 * d * up;
      const std::array<geometry::Pose, 2> X = Fixating(head, p_W);
      left.Deliver(runtime::ImageMessage{EyeImage("left", X[0])});
      right.Deliver(runtime::ImageMessage{EyeImage("right", X[1])});
      sent.reset();
      c->Step(runtime::StepContext{});
      ASSERT_TRUE(sent.has_value());
      ASSERT_EQ(sent->commands.size(), 2u);
      for (int eye = 0; eye < 2; ++eye) {
        const double distance = (p_W - X[eye].translation()).norm();
        EXPECT_EQ(sent->commands[eye].camera, eye == 0 ? "left" : "right");
        ASSERT_TRUE(sent->commands[eye].focus_m.has_value());
        EXPECT_NEAR(*sent->commands[eye].focus_m / distance, 1.0, kFocusTolerance)
            << file << " at " << d << " m, eye " << eye;
        EXPECT_FALSE(sent->commands[eye].exposure_s.has_value());
      }
    }
    // Parallel axes (or diverging): the far limit.
    const Eigen::Vector2d far = AccommodationComponent::FocusDistances(home[0], home[0], 0.1, 100);
    EXPECT_EQ(far[0], 100.0);
    EXPECT_EQ(far[1], 100.0);
  }
}

TEST(AccommodationTest, SimCamerasFocusAtTheVergenceDistanceOneFrameLater) {
  // POPEYE verging (eyes turned in by 3 degrees each): the frames' focus, two frames after
  // the component saw their poses, is the vergence distance of their own poses.
  const std::string scene = WriteScene("verging.yaml", R"(
background: [0.5, 0.5, 0.5]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
robot:
  head: )" + kSource + R"(/robots/popeye.yaml
  joints_deg: [0, 0, -3, 3]
  visible: false
  cameras:
    left: {calibration: {width: 32, height: 24, fx: 30, fy: 30}}
    right: {calibration: {width: 32, height: 24, fx: 30, fy: 30}}
)");
  const std::string pipeline = R"(
clock: {mode: simulated, step: 0.04, steps: 4}
threads: 1
components:
  - name: cameras
    type: sim.cameras
    params: {scene: )" + scene +
                               R"(, cameras: [left, right]}
    inputs: {controls: {from: focus.controls, delay: 1}}
  - name: focus
    type: camera.accommodation
    inputs: {left: cameras.left, right: cameras.right}
)";
  RegisterComponents();
  runtime::Pipeline built =
      runtime::Pipeline::Build(runtime::ParsePipeline(pipeline, "camera_controls_test"));
  std::vector<std::shared_ptr<const Image>> lefts, rights;
  for (const auto& c : built.components()) {
    for (const auto& o : c->outputs()) {
      if (auto* i = dynamic_cast<runtime::Output<runtime::ImageMessage>*>(o.get())) {
        i->signal().Connect([&](const runtime::ImageMessage& m) {
          (m.image->metadata().camera == "left" ? lefts : rights).push_back(m.image);
        });
      }
    }
  }
  runtime::RunPipeline(built);
  ASSERT_EQ(lefts.size(), 4u);
  EXPECT_EQ(lefts[0]->metadata().focus_m, 0.0);  // no lens, no command yet
  EXPECT_EQ(lefts[1]->metadata().focus_m, 0.0);
  const Eigen::Vector2d expected = AccommodationComponent::FocusDistances(
      *geometry::FindCameraPose(lefts[0]->metadata()),
      *geometry::FindCameraPose(rights[0]->metadata()), 0.1, 100.0);
  EXPECT_GT(expected[0], 0.5);
  EXPECT_LT(expected[0], 50.0);
  for (std::size_t s = 2; s < 4; ++s) {
    EXPECT_DOUBLE_EQ(lefts[s]->metadata().focus_m, expected[0]);
    EXPECT_DOUBLE_EQ(rights[s]->metadata().focus_m, expected[1]);
  }
}

}  // namespace
}  // namespace saccade::components
