#pragma once
// The simulated robot as pipeline components (seed Fig. 2, left block): the cameras rendered
// from a scene, and the head's motors. The real robot replaces them by components with the
// same ports (issue 7).
//
// Each declares its parameters in its constructor (docs/components.md is printed from them).
//
// sim.cameras -- renders the scene's cameras (seed: cameraCapture through the FBO), one image
//   output per camera of its `cameras` parameter.
//   inputs:  joints (head.joints, optional): the head's state at this step's time; connect
//            it from sim.head with delay 1. Without it, the scene's initial joints.
//   outputs: <camera> (runtime.image) per camera, shared; frame index = step.
//
// sim.head -- the head's four motors under their velocity and acceleration limits
//   (head/motors.h): saccades and smooth pursuit, never outside the joint limits.
//   Its scene's robot is the head (description, initial joints).
//   inputs:  command (head.command, optional): the latest command, applied when it arrives
//   outputs: joints (head.joints): the state at the end of the step (time + dt), i.e. at the
//            next step's time, which is when the cameras see it. The motors advance by the
//            time since the last state: dt in simulated time, the wall time in real time.
//   methods: state (runtime.empty -> head.joints): the joints now;
//            move (head.command -> head.joints): a command, as on the input, clamped to the
//              limits (the reply's targets say where it goes); NaN or infinite values fail;
//            stop (runtime.empty -> head.joints): brakes every joint and holds where it stops.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/head/motors.h"
#include "saccade/render/renderer.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

/// debug.fault -- fault injection, to see how a pipeline and its tools handle a failing
/// component: throws saccade::Error(`message`) in its Step at step `at_step` (and, with
/// `every: true`, at every later step). No ports.
class DebugFault : public runtime::Component {
 public:
  DebugFault();
  void Step(const runtime::StepContext& context) override;

 private:
  int64_t at_step_ = 0;
  bool every_ = false;
  std::string message_ = "injected fault";
};

class SimCameras : public runtime::Component, public EyeCamerasRole {
 public:
  SimCameras();
  void Start() override;
  void Step(const runtime::StepContext& context) override;
  void Stop() override;

  const scene::Scene& scene() const override { return *scene_; }
  /// Switches the scene's effects (the GUI's toggles); the next Step renders with them (it
  /// makes a new renderer). Call from the thread that runs the pipeline.
  void SetEffects(bool distortion, bool noise, bool motion_blur) override;
  const render::RendererOptions& options() const { return options_; }
  const render::RendererOptions* rendered() const override { return &options_; }

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  runtime::Input<JointStateMessage>& joints_;
  std::vector<runtime::Output<runtime::ImageMessage>*> outputs_;
  std::shared_ptr<const scene::Scene> scene_;
  render::RendererOptions options_;
  std::unique_ptr<render::Renderer> renderer_;
  bool options_changed_ = false;
};

class SimHead : public runtime::Component, public HeadRole {
 public:
  SimHead();
  void Start() override;
  void Step(const runtime::StepContext& context) override;

  const head::Motors& motors() const { return *motors_; }

  // HeadRole.
  JointStateMessage HeadState() override;
  JointStateMessage Move(const JointCommand& command) override;
  void StopHead() override;

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  head::Motors& Motors();  // throws when not started
  JointStateMessage State(double time) const;

  runtime::Input<JointCommand>& command_;
  runtime::Output<JointStateMessage>& joints_;
  std::shared_ptr<const scene::Scene> scene_;
  std::unique_ptr<head::Motors> motors_;
  double time_ = 0.0;  // s: the time of the state (after the last step)
};

}  // namespace saccade::components
