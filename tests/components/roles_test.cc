// The robot's roles (components/roles.h): a pipeline hands out its head and its eye cameras by
// interface, whatever implements them, and the applications command them through it, typed.

#include "saccade/components/roles.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "saccade/components/register.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::components {
namespace {

using ::testing::HasSubstr;

constexpr double kDeg = std::numbers::pi / 180.0;
const std::string kScene = std::string(SACCADE_SOURCE_DIR) + "/scenes/astronaut_and_cat.yaml";

runtime::Pipeline Build(const std::string& head_type, const std::string& head_params) {
  RegisterComponents();
  return runtime::Pipeline::LoadString("scene: " + kScene +
                                           "\ncomponents:\n"
                                           "  - {name: eyes, type: sim.cameras}\n"
                                           "  - {name: neck, type: " +
                                           head_type + ", params: {" + head_params + "}}\n",
                                       "roles.yaml");
}

TEST(RolesTest, APipelineHandsOutItsHeadAndCamerasByInterface) {
  runtime::Pipeline pipeline = Build("sim.head", "");
  std::string cameras_name, head_name;
  EyeCamerasRole* cameras = pipeline.FindRole<EyeCamerasRole>(&cameras_name);
  HeadRole* head = pipeline.FindRole<HeadRole>(&head_name);
  ASSERT_NE(cameras, nullptr);
  ASSERT_NE(head, nullptr);
  EXPECT_EQ(cameras_name, "eyes");
  EXPECT_EQ(head_name, "neck");
  // Rendered cameras: effects exist, the scene is the pipeline's (one object).
  ASSERT_NE(cameras->rendered(), nullptr);
  EXPECT_EQ(&cameras->scene(), pipeline.resources().Default<scene::Scene>("scene").get());
  EXPECT_FALSE(cameras->pair_counts().has_value());
  EXPECT_TRUE(IsRobotRole(*pipeline.Find("eyes")));
  EXPECT_EQ(pipeline.FindRole<runtime::Component>(), pipeline.Find("eyes"));  // any type works

  // The simulated head: typed commands, clamped to the limits; no emergency stop.
  pipeline.Find("neck")->Start();
  JointCommand far;
  far.positions = far.velocities = head::JointState::Popeye(0, 0, 0, 0);
  far.positions[0] = 150 * kDeg;  // beyond the 90 deg limit
  EXPECT_NEAR(head->Move(far).targets[0], 90 * kDeg, 1e-12);
  EXPECT_NEAR(head->HeadState().targets[0], 90 * kDeg, 1e-12);
  EXPECT_FALSE(head->has_emergency_stop());
  try {
    head->EmergencyStop();
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("no emergency stop"));
  }
  head->StopHead();  // brakes where it is: at rest, the target is the position
  EXPECT_NEAR(head->HeadState().targets[0], head->HeadState().positions[0], 1e-12);
}

TEST(RolesTest, AHardwareHeadStopsLatchesAndClearsThroughTheSameInterface) {
  runtime::Pipeline pipeline = Build("hw.head", "driver: simulated, watchdog_s: 0");
  HeadRole* head = pipeline.FindRole<HeadRole>();
  ASSERT_NE(head, nullptr);
  ASSERT_TRUE(head->has_emergency_stop());
  runtime::Component* component = pipeline.Find("neck");
  component->Start();
  JointCommand look;
  look.positions = look.velocities = head::JointState::Popeye(0, 0, 0, 0);
  look.positions[0] = 10 * kDeg;
  EXPECT_NEAR(head->Move(look).targets[0], 10 * kDeg, 1e-12);
  head->EmergencyStop();
  look.positions[0] = 20 * kDeg;
  EXPECT_THROW(head->Move(look), Error);  // latched until cleared
  head->ClearFault();
  EXPECT_NEAR(head->Move(look).targets[0], 20 * kDeg, 1e-12);
  component->Stop();
}

}  // namespace
}  // namespace saccade::components
