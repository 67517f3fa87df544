// remote.head and remote.cameras (components/remote_components.h): the robot of another
// process, here a sim.head and sim.cameras of the same pipeline connected port to port as the
// robot's topics would connect them (the DDS path: GuiCli.DdsAttachesToARobotInAnotherProcess...).

#include "saccade/components/remote_components.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "saccade/scene/scene.h"

namespace saccade::components {
namespace {

const std::string kScene = SACCADE_SOURCE_DIR "/scenes/portraits.yaml";

// The "robot" (sim.*) first; the remote side reads its state one step late, as from a topic.
const std::string kPipeline = R"(clock: {mode: simulated, step: 0.04, steps: 1}
scene: )" + kScene + R"(
components:
  - name: robot_head
    type: sim.head
    inputs: {command: {from: head.command, delay: 1}}
  - name: robot_cameras
    type: sim.cameras
    params: {distortion: false, noise: false, motion_blur: false}
    inputs: {joints: {from: robot_head.joints, delay: 1}}
  - name: cameras
    type: remote.cameras
    inputs: {left: robot_cameras.left, right: robot_cameras.right}
  - name: head
    type: remote.head
    inputs: {state: robot_head.joints}
)";

TEST(RemoteComponents, TheHeadSendsClampedCommandsAndReportsTheRobotsState) {
  RegisterComponents();
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(kPipeline, "remote_test.yaml");
  auto* head = pipeline.Find<RemoteHead>("head");
  ASSERT_NE(head, nullptr);
  // No state yet: the role says so rather than make one up.
  try {
    head->HeadState();
    FAIL() << "a state before the robot sent one";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no joint state"), std::string::npos) << e.what();
  }
  const scene::Scene scene = scene::Scene::Load(kScene);
  const double pan_max = scene.robot()->head.joint(0).limits.max;
  int64_t images = 0;
  runtime::RunOptions run;
  run.steps = 30;
  run.after_step = [&](const runtime::StepContext& context) {
    if (context.step == 1) {
      EXPECT_EQ(head->HeadState().positions[0], 0.0);
      JointCommand far;
      far.positions = far.velocities = head::JointState::Popeye(0, 0, 0, 0);
      far.positions[0] = 10.0;  // beyond the limit: clamped here
      EXPECT_DOUBLE_EQ(head->Move(far).targets[0], pan_max);
      JointCommand bad;
      bad.positions = bad.velocities = head::JointState::Popeye(0, 0, 0, 0);
      bad.positions[1] = std::numeric_limits<double>::quiet_NaN();
      EXPECT_THROW(head->Move(bad), Error);
    }
  };
  for (const auto& output : pipeline.Find("cameras")->outputs()) {
    if (auto* typed = dynamic_cast<runtime::Output<runtime::ImageMessage>*>(output.get())) {
      typed->signal().Connect(
          [&images](const runtime::ImageMessage& m) { images += m.image != nullptr; });
    }
  }
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, run);
  EXPECT_TRUE(summary.errors.empty());
  // The robot went to the clamped target, and the remote state says so.
  EXPECT_NEAR(head->HeadState().positions[0], pan_max, 1e-6);
  EXPECT_EQ(images, 2 * 30);  // every image of both eyes passed on
  EXPECT_NE(pipeline.Find<RemoteCameras>("cameras")->Describe().find("30 + 30"), std::string::npos);
}

}  // namespace
}  // namespace saccade::components
