#pragma once
// The robot of another process (issue 16: the GUI attached to a running robot over DDS): the
// head and eye cameras as pipeline components whose ports the pipeline file connects to the
// robot process's topics (pipelines/remote.yaml). They play the robot's roles (roles.h), so
// that the GUI and the perception loop use them as they use sim.* and hw.*; no DDS here.
//
// remote.head -- the head of a robot process.
//   Its scene's robot is the head (the joint limits commands are clamped to).
//   inputs:  state (head.joints): the robot's state (topic joint_states);
//            command (head.command, optional): this process's perception loop
//   outputs: joints (head.joints): the robot's state, again, when a new one came;
//            command (head.command): what goes to the robot (topic head/command): the input
//            command, or the role's Move and StopHead (the GUI's), one per step at most
//   HeadRole: HeadState is the newest state received (Error before the first);
//            Move clamps to the limits and sends at the next step.
// remote.cameras -- the eye cameras of a robot process.
//   inputs:  left, right (runtime.image): the robot's images (topics left/image_raw, ...),
//            with their camera model and pose (from camera_info and /tf)
//   outputs: left, right (runtime.image): each image received, as it came
// Parameters: declared in the constructors (docs/components.md).
#include <memory>
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

class RemoteHead : public runtime::Component, public HeadRole {
 public:
  RemoteHead();
  void Step(const runtime::StepContext& context) override;

  // HeadRole.
  JointStateMessage HeadState() override;
  JointStateMessage Move(const JointCommand& command) override;
  void StopHead() override;

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  runtime::Input<JointStateMessage>& state_;
  runtime::Input<JointCommand>& command_in_;
  runtime::Output<JointStateMessage>& joints_;
  runtime::Output<JointCommand>& command_out_;
  std::shared_ptr<const scene::Scene> scene_;
  std::optional<JointCommand> pending_;  // the role's command, sent at the next step
  std::optional<JointStateMessage> state_now_;
  double time_ = 0.0;
};

class RemoteCameras : public runtime::Component, public EyeCamerasRole {
 public:
  RemoteCameras();
  void Step(const runtime::StepContext& context) override;
  /// The scene whose robot carries the cameras (not what they see).
  const scene::Scene& scene() const override { return *scene_; }
  std::string Describe() const override;

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  runtime::Input<runtime::ImageMessage>& left_in_;
  runtime::Input<runtime::ImageMessage>& right_in_;
  runtime::Output<runtime::ImageMessage>& left_;
  runtime::Output<runtime::ImageMessage>& right_;
  std::shared_ptr<const scene::Scene> scene_;
  int64_t received_[2] = {0, 0};
};

}  // namespace saccade::components
