#include "saccade/components/remote_components.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "components/internal_scene.h"
#include "saccade/core/error.h"

namespace saccade::components {

RemoteHead::RemoteHead()
    : state_(AddInput<JointStateMessage>("state")),
      command_in_(AddInput<JointCommand>("command")),
      joints_(AddOutput<JointStateMessage>("joints")),
      command_out_(AddOutput<JointCommand>("command")) {
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
}

void RemoteHead::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  scene_ = scene.scene;
  internal::RobotOf(*scene_, scene.path);
}

JointStateMessage RemoteHead::HeadState() {
  if (!state_now_) {
    throw Error(
        fmt::format("{}: no joint state has come from the robot yet (is it running, on "
                    "this DDS domain?)",
                    name()));
  }
  JointStateMessage state = *state_now_;
  if (pending_) {  // where it was just told to go
    state.targets = pending_->positions;
    state.target_velocities = pending_->velocities;
  }
  return state;
}

JointStateMessage RemoteHead::Move(const JointCommand& command) {
  const head::HeadModel& head = scene_->robot()->head;
  JointCommand clamped = command;
  try {
    clamped.positions = head.Arrange(command.positions);
    clamped.velocities = command.velocities.empty() ? head::JointState(head.joint_names())
                                                    : head.Arrange(command.velocities);
  } catch (const InvalidArgument& error) {
    throw Error(fmt::format("{}: {}", name(), error.what()));
  }
  for (int j = 0; j < head.num_joints(); ++j) {
    if (!std::isfinite(clamped.positions[j]) || !std::isfinite(clamped.velocities[j])) {
      throw Error(
          fmt::format("{}: the command's {} is not a finite number", name(), head.joint_name(j)));
    }
    const head::JointSettings& s = head.joint(j);
    clamped.positions[j] =
        s.driven ? std::clamp(clamped.positions[j], s.limits.min, s.limits.max) : s.hold;
  }
  clamped.time = time_;
  pending_ = clamped;
  return HeadState();
}

void RemoteHead::StopHead() {
  // Hold where the robot said it is; the robot's own motors brake at their limits.
  JointCommand hold;
  hold.time = time_;
  hold.positions = HeadState().positions;
  pending_ = hold;
}

void RemoteHead::Step(const runtime::StepContext& context) {
  time_ = context.time;
  if (state_.fresh()) {
    state_now_ = state_.value();
    joints_.Emit(*state_now_);
  }
  // This process's perception loop, or the role's command (the GUI's) when it came since.
  if (command_in_.fresh()) pending_ = command_in_.value();
  if (pending_) {
    command_out_.Emit(*pending_);
    pending_.reset();
  }
}

RemoteCameras::RemoteCameras()
    : left_in_(AddInput<runtime::ImageMessage>("left")),
      right_in_(AddInput<runtime::ImageMessage>("right")),
      left_(AddOutput<runtime::ImageMessage>("left")),
      right_(AddOutput<runtime::ImageMessage>("right")) {
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
}

void RemoteCameras::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  scene_ = scene.scene;
  internal::RobotOf(*scene_, scene.path);
}

std::string RemoteCameras::Describe() const {
  return fmt::format("{} + {} images received from the robot process", received_[0], received_[1]);
}

void RemoteCameras::Step(const runtime::StepContext&) {
  if (left_in_.fresh() && left_in_.value().image) {
    ++received_[0];
    left_.Emit(left_in_.value());
  }
  if (right_in_.fresh() && right_in_.value().image) {
    ++received_[1];
    right_.Emit(right_in_.value());
  }
}

}  // namespace saccade::components
