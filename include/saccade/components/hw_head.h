#pragma once
// The real robot as pipeline components (issue 7; seed Fig. 2: popeyeRobot and the camera
// acquisition): the same component names and ports as sim.head and sim.cameras, so that a
// hardware file (runtime/pipeline.h) swaps one for the other.
//
// hw.head -- a head driver (hw/head_driver.h) as the pipeline's head, with the driver's
//   safety rules: non-finite commands rejected, targets clamped to the joint limits and
//   velocities limited (reported), the watchdog, the emergency stop, faults.
//   Its scene's robot is the head (its head description, with the servo mapping for
//   dynamixel). Parameters: declared in the constructor (docs/components.md). Mirror mode
//   (seed: popeyeRobot): commands move a virtual (simulated) head, which is what the cameras
//   see and what `joints` reports; the device follows the virtual head every step.
//   inputs:  command (head.command, optional): sent to the device (or the virtual head).
//   outputs: joints (head.joints): the device's measured joints (mirror: the virtual
//              head's) at the step's time; status (head.status): the driver's safety state.
//   methods: state (runtime.empty -> head.joints), move (head.command -> head.joints),
//            stop (runtime.empty -> head.status): brake and hold,
//            estop (runtime.empty -> head.status): emergency stop, latched until `clear`,
//            clear (runtime.empty -> head.status): clears an emergency stop or a fault,
//            torque_on / torque_off (runtime.empty -> head.status).
//   A device moves on the wall clock whatever the pipeline's clock: under a simulated clock
//   whose steps take longer than `step` (rendering on llvmpipe), the head arrives sooner in
//   simulated time than sim.head would; run in real time (`saccade demo --realtime`) for
//   timings.
//   A fault (a servo's overload, a servo that stops answering, ...) does not stop the
//   pipeline: the head holds, commands are rejected and counted, `status` names the fault,
//   and it is logged once (core/log.h, level error).
#include <memory>
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/head/motors.h"
#include "saccade/hw/head_driver.h"
#include "saccade/hw/stereo_source.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

class HwHead : public runtime::Component, public HeadRole {
 public:
  HwHead();
  void Start() override;
  void Step(const runtime::StepContext& context) override;
  void Stop() override;

  /// The driver, once started (tests, tools).
  hw::HeadDriver* driver() { return driver_.get(); }

  // HeadRole.
  JointStateMessage HeadState() override;
  JointStateMessage Move(const JointCommand& command) override;
  void StopHead() override;
  bool has_emergency_stop() const override { return true; }
  void EmergencyStop() override;
  void ClearFault() override;

 protected:
  void Configured() override;

 private:
  hw::HeadDriver& Driver();  // throws when not started
  void Send(const head::JointState& positions, const head::JointState& velocities);
  JointStateMessage Joints(const hw::HeadStatus& status, double time) const;
  HeadStatusMessage Status(const hw::HeadStatus& status, double time) const;
  void Report(const hw::HeadStatus& status);

  runtime::Input<JointCommand>& command_;
  runtime::Output<JointStateMessage>& joints_;
  runtime::Output<HeadStatusMessage>& status_;
  std::shared_ptr<const scene::Scene> scene_;
  std::string scene_param_;
  std::string driver_kind_;
  std::string port_;
  int baud_ = 1000000;
  double timeout_ms_ = 20.0;
  int retries_ = 2;
  hw::SafetyOptions safety_;
  bool mirror_ = false;

  std::unique_ptr<hw::HeadDriver> driver_;
  std::unique_ptr<head::Motors> virtual_;  // mirror mode
  double time_ = 0.0;
  std::string reported_fault_;
  std::string last_limit_;
  std::string last_rejection_;
};

}  // namespace saccade::components
