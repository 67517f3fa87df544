#pragma once
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
// Parameters: declared in the constructor (docs/components.md lists them).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/head/motors.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

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
