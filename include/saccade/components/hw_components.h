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
//
// hw.cameras -- the eye cameras as real camera sources (hw/camera_source.h: V4L2 devices,
//   GStreamer pipelines, IIDC cameras, video files, image sequences and lists), paired by
//   time stamp (hw/stereo_source.h), delivering the same images with the same metadata as
//   sim.cameras: K and distortion from each camera's calibration file, X_WC and the joints
//   from the head's forward kinematics at the joints of this step.
//   Its scene's robot carries the cameras. Parameters: declared in the constructor
//   (docs/components.md); each camera's SOURCE map is read by a table of its own.
//   inputs:  joints (head.joints, optional; connect with delay 1 as for sim.cameras)
//   outputs: left, right (runtime.image): one pair per step; time = the step's time (the
//            capture time stays in the source: frame_index counts the pairs delivered)
//   When a file or list ends (without loop), nothing more is emitted and a log line (info)
//   says so; a device error stops the pipeline with the camera and its uri named.
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

class HwCameras : public runtime::Component, public EyeCamerasRole {
 public:
  HwCameras();
  void Start() override;
  void Step(const runtime::StepContext& context) override;
  void Stop() override;

  /// The pair source, once started (tests, tools).
  const hw::StereoSource* source() const { return source_.get(); }
  /// The scene whose robot carries the cameras (not what they see).
  const scene::Scene& scene() const override { return *scene_; }
  /// Pairs delivered, and frames dropped for want of a partner within max_skew_s, so far.
  int64_t pairs() const { return pairs_; }
  int64_t dropped_left() const { return dropped_left_; }
  int64_t dropped_right() const { return dropped_right_; }
  /// A line for people: "25 pairs from <left uri> and <right uri>, 0 + 0 frames dropped".
  std::string Describe() const override;
  std::optional<CameraPairCounts> pair_counts() const override {
    return CameraPairCounts{pairs_, dropped_left_, dropped_right_};
  }

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  nlohmann::json cameras_;
  runtime::Input<JointStateMessage>& joints_;
  runtime::Output<runtime::ImageMessage>& left_;
  runtime::Output<runtime::ImageMessage>& right_;
  std::shared_ptr<const scene::Scene> scene_;
  hw::CameraSourceSpec left_spec_;
  hw::CameraSourceSpec right_spec_;
  double max_skew_s_ = 0.02;
  std::unique_ptr<hw::StereoSource> source_;
  bool ended_ = false;
  int64_t pairs_ = 0;
  int64_t dropped_left_ = 0;
  int64_t dropped_right_ = 0;
};

}  // namespace saccade::components
