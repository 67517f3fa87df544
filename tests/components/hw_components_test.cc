// The real robot's components (hw_components.h) in pipelines: hw.cameras on recorded images
// (OpenCV's stereo pair, and rendered portraits played back as files with their calibration
// files), and hw.head on the simulated driver and on the emulated Dynamixel bus.
#include "saccade/components/hw_components.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "image_camera_helpers.h"
#include "saccade/components/demo/face_truth.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/head/kinematics.h"
#include "saccade/render/renderer.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {
namespace {

namespace fs = std::filesystem;
using demo::FaceCentreAt;
using demo::FindPictureFaces;
using demo::PictureFace;
using nlohmann::json;

const std::string kSource = SACCADE_SOURCE_DIR;
const std::string kScene = kSource + "/scenes/astronaut_and_cat.yaml";
const std::string kOpenCvData = "/usr/share/doc/opencv-doc/examples/data";
constexpr double kDeg = 3.14159265358979323846 / 180.0;

// A folder of its own per test, removed at the end.
class HwComponentsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RegisterComponents();
    dir_ = fs::temp_directory_path() /
           (std::string("saccade_hw_components_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// Every message of type T sent by any output of the pipeline.
template <typename T>
std::shared_ptr<std::vector<T>> CaptureAll(const runtime::Pipeline& pipeline) {
  auto all = std::make_shared<std::vector<T>>();
  for (const auto& c : pipeline.components()) {
    for (const auto& output : c->outputs()) {
      if (auto* typed = dynamic_cast<runtime::Output<T>*>(output.get())) {
        typed->signal().Connect([all](const T& m) { all->push_back(m); });
      }
    }
  }
  return all;
}

TEST_F(HwComponentsTest, OpenCvStereoPairArrivesCalibratedAndPlacedOnTheHead) {
  const std::string text = R"(clock: {mode: simulated, step: 0.04, steps: 15}
components:
  - name: cameras
    type: hw.cameras
    params:
      scene: )" + kScene + R"(
      cameras:
        left: {uri: "list:)" +
                           kOpenCvData + R"(/stereo_calib.xml", first: 0, every: 2,
               calibration: )" +
                           kOpenCvData + R"(/intrinsics.yml, calibration_index: 1}
        right: {uri: "list:)" +
                           kOpenCvData + R"(/stereo_calib.xml", first: 1, every: 2,
                calibration: )" +
                           kOpenCvData + R"(/intrinsics.yml, calibration_index: 2}
    inputs: {joints: {from: head.joints, delay: 1}}
  - name: head
    type: sim.head
    params: {scene: )" + kScene +
                           R"(}
)";
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(text, (dir_ / "p.yaml").string());
  const auto images = CaptureAll<runtime::ImageMessage>(pipeline);
  JointCommand look;
  look.positions = look.velocities = head::JointState::Popeye(0, 0, 0, 0);
  look.positions = head::JointState::Popeye(20 * kDeg, -5 * kDeg, -2 * kDeg, 2 * kDeg);
  // Move the head, so that X_WC must follow the joints.
  runtime::RunOptions run;
  run.after_step = [&](const runtime::StepContext& context) {
    if (context.step == 2) {
      pipeline.Call("head", "move", runtime::MessageTraits<JointCommand>::ToJson(look));
    }
  };
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, run);
  EXPECT_TRUE(summary.errors.empty());
  // 13 pairs in the list (no 10), then the end: nothing more.
  ASSERT_EQ(images->size(), 26u);
  const std::shared_ptr<const scene::Scene> scene =
      std::make_shared<const scene::Scene>(scene::Scene::Load(kScene));
  const head::HeadModel& head = scene->robot()->head;
  for (std::size_t i = 0; i < images->size(); i += 2) {
    const Image& left = *(*images)[i].image;
    const Image& right = *(*images)[i + 1].image;
    EXPECT_EQ(left.metadata().camera, "left");
    EXPECT_EQ(right.metadata().camera, "right");
    EXPECT_EQ(left.metadata().frame_index, static_cast<int64_t>(i / 2));
    EXPECT_EQ(left.width(), 640);
    EXPECT_EQ(left.height(), 480);
    // K and distortion from intrinsics.yml: M1 D1 and M2 D2.
    EXPECT_DOUBLE_EQ(testing_helpers::KAt(left.metadata(), 2), 3.3568643204394891e+02);
    EXPECT_DOUBLE_EQ(testing_helpers::KAt(right.metadata(), 2), 3.3455744527912015e+02);
    EXPECT_DOUBLE_EQ(testing_helpers::Coefficients(left.metadata())[0], 2.9589439552724328e-01);
    EXPECT_DOUBLE_EQ(testing_helpers::Coefficients(right.metadata())[0], -1.6916358306948096e-01);
    // X_WC: the head's forward kinematics at the joints the image was taken at.
    ASSERT_TRUE(left.metadata().has_joints);
    const auto& q = left.metadata().joints;
    const head::HeadFrames frames =
        head::ForwardKinematics(*head.AppendixAHead(), head::PopeyeJoints{q[0], q[1], q[2], q[3]});
    EXPECT_TRUE(vision::CameraPoseOf(left).matrix().isApprox(frames.X_WCamLeft.matrix(), 1e-12));
    EXPECT_TRUE(vision::CameraPoseOf(right).matrix().isApprox(frames.X_WCamRight.matrix(), 1e-12));
  }
  // The head moved after step 2: the later frames ride on it.
  const auto& last = (*images)[24].image->metadata().joints;
  EXPECT_NEAR(last[0], 20 * kDeg, 1e-6);
  EXPECT_NEAR((*images)[0].image->metadata().joints[0], 0.0, 1e-12);
}

TEST_F(HwComponentsTest, RenderedPortraitsPlayedAsRealCamerasTriangulateTheFace) {
  // "Real" camera files: the simulator's two eye images of the portraits, written as PNG with
  // a calibration file each -- then read back by hw.cameras and run through the perception
  // components, which know nothing of the scene.
  const std::shared_ptr<const scene::Scene> scene =
      std::make_shared<const scene::Scene>(scene::Scene::Load(kScene));
  {
    render::RendererOptions options;
    options.cameras = {"left", "right"};
    const std::unique_ptr<render::Renderer> renderer = render::MakeRenderer(*scene, options);
    const std::vector<render::Frame> frames = renderer->Render(scene->InitialState(), 0);
    for (const render::Frame& frame : frames) {
      const std::string camera = frame.color->metadata().camera;
      WritePng(frame.color->view(), dir_ / (camera + ".png"));
      geometry::WriteCameraCalibration({vision::CameraModelOf(*frame.color), camera},
                                       dir_ / (camera + ".yml"),
                                       geometry::CalibrationFormat::kOpenCvYaml);
    }
  }
  const std::string text = R"(clock: {mode: simulated, step: 0.04, steps: 3}
components:
  - name: cameras
    type: hw.cameras
    params:
      scene: )" + kScene + R"(
      cameras:
        left: {uri: left.png, calibration: left.yml, loop: true}
        right: {uri: right.png, calibration: right.yml, loop: true}
  - name: faces_left
    type: vision.face_detector
    inputs: {image: cameras.left}
  - name: faces_right
    type: vision.face_detector
    inputs: {image: cameras.right}
  - name: stereo
    type: vision.stereo_faces
    inputs: {left: faces_left.faces, right: faces_right.faces}
)";
  const fs::path pipeline_file = dir_ / "p.yaml";
  std::ofstream(pipeline_file) << text;
  runtime::Pipeline pipeline = runtime::Pipeline::LoadFile(pipeline_file.string());
  const auto candidates = CaptureAll<CandidatesMessage>(pipeline);
  runtime::RunPipeline(pipeline, {});
  ASSERT_EQ(candidates->size(), 3u);  // one pair per step, looping over the one still image
  std::optional<PictureFace> astronaut;
  for (const PictureFace& p : FindPictureFaces(*scene)) {
    if (p.has_face) astronaut = p;
  }
  ASSERT_TRUE(astronaut);
  const Eigen::Vector3d truth = FaceCentreAt(*scene, *astronaut, 0.0);
  for (const CandidatesMessage& m : *candidates) {
    ASSERT_EQ(m.candidates.size(), 1u) << "the astronaut, and not the cat";
    // Detections quantise to pixels: a few centimetres in depth at 2.2 m (components_test).
    EXPECT_LT((m.candidates[0].p_W - truth).norm(), 0.03)
        << m.candidates[0].p_W.transpose() << " vs " << truth.transpose();
  }
}

TEST_F(HwComponentsTest, CameraParamsErrorsNameTheField) {
  const auto error = [&](const std::string& cameras) {
    const std::string text =
        "clock: {mode: simulated, step: 0.04, steps: 1}\ncomponents:\n  - name: cameras\n    type: "
        "hw.cameras\n    params: "
        "{scene: " +
        kScene + ", cameras: " + cameras + "}\n";
    try {
      runtime::Pipeline pipeline = runtime::Pipeline::LoadString(text, "p.yaml");
      // Start errors end the run; the summary names the component.
      const runtime::RunSummary summary = runtime::RunPipeline(pipeline, {});
      if (!summary.errors.empty()) return summary.errors.front().ToString();
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    ADD_FAILURE() << "no error for " << cameras;
    return std::string();
  };
  const auto expect = [](const std::string& message, const std::string& part) {
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  };
  expect(error("{left: {uri: a.png}}"), "parameter 'cameras': missing camera 'right'");
  expect(error("{left: {uri: a.png}, right: {uri: b.png}, middle: {uri: c.png}}"),
         "unknown camera 'middle'");
  expect(error("{left: {url: a.png}, right: {uri: b.png}}"), "parameter 'cameras.left.");
  expect(error("{left: {uri: a.png, every: 0}, right: {uri: b.png}}"),
         "parameter 'cameras.left.every'");
  // A missing file fails when the pipeline starts, naming the camera and the file.
  expect(error("{left: {uri: nowhere.png}, right: {uri: nowhere.png}}"), "nowhere.png");
}

TEST_F(HwComponentsTest, SimulatedDriverHeadClampsAndReportsAndStopsOnCommand) {
  const std::string text = R"(clock: {mode: simulated, step: 0.04, steps: 5}
components:
  - name: head
    type: hw.head
    params: {scene: )" + kScene +
                           R"(, driver: simulated, watchdog_s: 0}
)";
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(text, "p.yaml");
  const auto statuses = CaptureAll<HeadStatusMessage>(pipeline);
  const auto joints = CaptureAll<JointStateMessage>(pipeline);
  runtime::RunOptions run;
  run.after_step = [&](const runtime::StepContext& context) {
    if (context.step != 0) return;
    JointCommand far;
    far.positions = far.velocities = head::JointState::Popeye(0, 0, 0, 0);
    far.positions[0] = 150 * kDeg;  // beyond the 90 deg limit
    const json reply =
        pipeline.Call("head", "move", runtime::MessageTraits<JointCommand>::ToJson(far));
    EXPECT_NEAR(reply["targets"]["pan"].get<double>(), 90 * kDeg, 1e-12);
    JointCommand nan;
    nan.positions = nan.velocities = head::JointState::Popeye(0, 0, 0, 0);
    nan.positions[1] = std::nan("");
    const auto* move = pipeline.Find("head")->FindMethod<JointCommand, JointStateMessage>("move");
    ASSERT_NE(move, nullptr);
    try {
      move->Call(nan);  // typed: JSON has no NaN
      ADD_FAILURE() << "a NaN command was accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("not a finite number"), std::string::npos) << e.what();
    }
    const json stopped = pipeline.Call("head", "estop", json::object());
    EXPECT_TRUE(stopped["emergency_stopped"].get<bool>());
  };
  runtime::RunPipeline(pipeline, run);
  ASSERT_EQ(statuses->size(), 5u);
  const HeadStatusMessage& last = statuses->back();
  EXPECT_EQ(last.driver, "simulated");
  EXPECT_EQ(last.commands, 1);
  EXPECT_EQ(last.limited_commands, 1);
  EXPECT_EQ(last.rejected_commands, 1);  // the NaN
  EXPECT_TRUE(last.emergency_stopped);
  EXPECT_NE(last.last_limit.find("pan target 150.00 deg clamped to 90.00 deg"), std::string::npos)
      << last.last_limit;
  EXPECT_LE(joints->back().positions[0], 90 * kDeg);
}

}  // namespace
}  // namespace saccade::components
