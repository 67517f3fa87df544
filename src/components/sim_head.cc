#include "saccade/components/sim_head.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "components/internal_scene.h"
#include "saccade/core/error.h"

namespace saccade::components {

SimHead::SimHead()
    : command_(AddInput<JointCommand>("command")), joints_(AddOutput<JointStateMessage>("joints")) {
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  // The methods (for scripts and other processes) are the HeadRole's, by name.
  AddMethod<runtime::Empty, JointStateMessage>(
      "state", [this](const runtime::Empty&) { return HeadState(); },
      "the joints now (positions, velocities, targets)");
  AddMethod<JointCommand, JointStateMessage>(
      "move", [this](const JointCommand& command) { return Move(command); },
      "a saccade or pursuit command, clamped to the joint limits; replies with the targets");
  AddMethod<runtime::Empty, JointStateMessage>(
      "stop",
      [this](const runtime::Empty&) {
        StopHead();
        return HeadState();
      },
      "brakes every joint and holds where it stops");
}

JointStateMessage SimHead::HeadState() {
  Motors();  // throws when not started
  return State(time_);
}

JointStateMessage SimHead::Move(const JointCommand& command) {
  Motors().SetTarget(command.positions, command.velocities);  // clamps, or throws on NaN
  return State(time_);
}

void SimHead::StopHead() {
  // Brake every joint at its acceleration limit and hold where it stops.
  Motors().Reset(motors_->positions(), motors_->velocities());
}

head::Motors& SimHead::Motors() {
  if (!motors_) throw Error("the head is not started");
  return *motors_;
}

JointStateMessage SimHead::State(double time) const {
  JointStateMessage out;
  out.time = time;
  out.positions = motors_->positions();
  out.velocities = motors_->velocities();
  out.targets = motors_->targets();
  out.target_velocities = motors_->target_velocities();
  out.arrived = motors_->Arrived(1e-4);
  out.clamped_commands = motors_->clamped_commands();
  out.head = std::shared_ptr<const head::HeadModel>(scene_, &scene_->robot()->head);
  return out;
}

void SimHead::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  scene_ = scene.scene;
  internal::RobotOf(*scene_, scene.path);
}

void SimHead::Start() {
  const scene::Robot& robot = *scene_->robot();
  motors_ = std::make_unique<head::Motors>(robot.head, robot.initial_joints);
  time_ = 0.0;
}

void SimHead::Step(const runtime::StepContext& context) {
  if (command_.fresh()) {
    const JointCommand& command = command_.value();
    // Motors clamp targets to the joint limits and count it; non-finite values throw.
    motors_->SetTarget(command.positions, command.velocities);
  }
  // Up to the next step's time. Simulated: dt. Real time: the wall time that has passed, so
  // that the head moves at its real speed however long the loop's steps take.
  const double until = context.time + context.dt;
  motors_->Step(std::max(0.0, until - time_));
  time_ = until;
  joints_.Emit(State(time_));
}

}  // namespace saccade::components
