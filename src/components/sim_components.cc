#include "saccade/components/sim_components.h"

#include <algorithm>
#include <cstdint>

#include "components/internal_scene.h"
#include "saccade/core/error.h"

namespace saccade::components {

DebugFault::DebugFault() {
  DeclareParam("at_step", &at_step_, "the step at which Step throws").Min(0).Required();
  DeclareParam("message", &message_, "the error's message");
  DeclareParam("every", &every_, "throw at every later step too");
}

void DebugFault::Step(const runtime::StepContext& context) {
  if (context.step == at_step_ || (every_ && context.step > at_step_)) throw Error(message_);
}

SimCameras::SimCameras() : joints_(AddInput<JointStateMessage>("joints")) {
  options_.cameras = {"left", "right"};
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("cameras", &options_.cameras,
               "the scene's cameras to render, one image output each, named as the camera");
  DeclareParam("distortion", &options_.distortion, "the calibrations' lens distortion");
  DeclareParam("noise", &options_.noise, "sensor noise, seeded per camera and frame");
  DeclareParam("motion_blur", &options_.motion_blur, "blur over each camera's exposure");
  DeclareParam("msaa", &options_.msaa_samples, "multisample anti-aliasing: 0, 2, 4 or 8 samples")
      .Range(0, 8);
  DeclareParam("lod_max_error_px", &options_.lod_max_error_px,
               "level of detail: the largest screen error of a simplified model")
      .Range(0.0, 1e6)
      .Unit("px");
}

void SimCameras::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  const std::string& path = scene.path;
  std::string error;
  if (!options_.IsValid(&error)) throw InvalidArgument(error);
  scene_ = scene.scene;
  for (const std::string& camera : options_.cameras) {
    if (scene_->FindCamera(camera) == nullptr) {
      throw InvalidArgument("parameter 'cameras': scene '" + path + "' has no camera '" + camera +
                            "'");
    }
    outputs_.push_back(&AddOutput<runtime::ImageMessage>(camera));
  }
}

void SimCameras::Start() { renderer_ = render::MakeRenderer(*scene_, options_); }

void SimCameras::SetEffects(bool distortion, bool noise, bool motion_blur) {
  if (options_.distortion == distortion && options_.noise == noise &&
      options_.motion_blur == motion_blur) {
    return;
  }
  options_.distortion = distortion;
  options_.noise = noise;
  options_.motion_blur = motion_blur;
  options_changed_ = true;
}

void SimCameras::Step(const runtime::StepContext& context) {
  if (options_changed_ && renderer_) {
    renderer_.reset();  // one GL context at a time
    renderer_ = render::MakeRenderer(*scene_, options_);
    options_changed_ = false;
  }
  scene::SceneState state = scene_->InitialState();
  state.time = context.time;
  if (const JointStateMessage* joints = joints_.get()) {
    state.joints = joints->positions;
    state.joint_velocities = joints->velocities;
  }
  std::vector<render::Frame> frames = renderer_->Render(state, context.step);
  for (std::size_t i = 0; i < frames.size() && i < outputs_.size(); ++i) {
    outputs_[i]->Emit(runtime::ImageMessage{frames[i].color});
  }
}

void SimCameras::Stop() { renderer_.reset(); }

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
  out.arrived = motors_->Arrived(1e-4);
  out.clamped_commands = motors_->clamped_commands();
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
