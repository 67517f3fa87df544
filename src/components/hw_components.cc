#include "saccade/components/hw_components.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "components/internal_scene.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/head/kinematics.h"
#include "saccade/hw/dynamixel_head.h"

namespace saccade::components {

HwHead::HwHead()
    : command_(AddInput<JointCommand>("command")),
      joints_(AddOutput<JointStateMessage>("joints")),
      status_(AddOutput<HeadStatusMessage>("status")) {
  // The methods (for scripts and other processes) are the HeadRole's, by name.
  AddMethod<runtime::Empty, JointStateMessage>(
      "state", [this](const runtime::Empty&) { return HeadState(); },
      "the joints now (measured; the virtual head's in mirror mode)");
  AddMethod<JointCommand, JointStateMessage>(
      "move", [this](const JointCommand& command) { return Move(command); },
      "a saccade or pursuit command, checked, clamped and limited by the driver");
  AddMethod<runtime::Empty, HeadStatusMessage>(
      "stop",
      [this](const runtime::Empty&) {
        StopHead();
        return Status(Driver().Read(), time_);
      },
      "brakes every joint and holds where it stops");
  AddMethod<runtime::Empty, HeadStatusMessage>(
      "estop",
      [this](const runtime::Empty&) {
        EmergencyStop();
        return Status(Driver().Read(), time_);
      },
      "emergency stop: holds and rejects every command until `clear`");
  AddMethod<runtime::Empty, HeadStatusMessage>(
      "clear",
      [this](const runtime::Empty&) {
        ClearFault();
        return Status(Driver().Read(), time_);
      },
      "clears an emergency stop or a fault (reboots faulty servos); holds where it is");
  AddMethod<runtime::Empty, HeadStatusMessage>(
      "torque_on",
      [this](const runtime::Empty&) {
        Driver().SetTorque(true);
        return Status(Driver().Read(), time_);
      },
      "powers the motors; they hold where they are");
  AddMethod<runtime::Empty, HeadStatusMessage>(
      "torque_off",
      [this](const runtime::Empty&) {
        Driver().SetTorque(false);
        return Status(Driver().Read(), time_);
      },
      "unpowers the motors (the joints can be moved by hand)");
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("driver", &driver_kind_,
               "dynamixel: the servos on a serial bus; simulated: the simulated motors on the "
               "wall clock, to try a pipeline without a device")
      .Choices({"dynamixel", "simulated"})
      .Required();
  DeclareParam("port", &port_,
               "the serial port (dynamixel, required), e.g. /dev/ttyUSB0, or the path "
               "saccade-servo-emulator prints");
  DeclareParam("baud", &baud_, "the bus's baud rate").Range(9600, 10500000).Unit("baud");
  DeclareParam("timeout_ms", &timeout_ms_, "each bus transaction's time-out")
      .Range(0.1, 10000.0)
      .Unit("ms");
  DeclareParam("retries", &retries_, "retries of a failed bus transaction").Range(0, 100);
  DeclareParam("watchdog_s", &safety_.watchdog_s,
               "with no command for this long the head holds; 0: off")
      .Range(0.0, 3600.0)
      .Unit("s");
  DeclareParam("mirror", &mirror_,
               "commands move a virtual head (what the cameras see and `joints` reports); the "
               "device follows it every step, within its limits");
}

void HwHead::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  const std::string& path = scene.path;
  if (driver_kind_ == "dynamixel" && port_.empty()) {
    throw InvalidArgument(
        "parameter 'port' is required for the dynamixel driver (the serial port, e.g. "
        "/dev/ttyUSB0, or the path saccade-servo-emulator prints)");
  }
  scene_ = scene.scene;
  const scene::Robot& robot = internal::RobotOf(*scene_, path);
  if (driver_kind_ == "dynamixel" && !robot.head.HasServos()) {
    throw InvalidArgument(fmt::format(
        "the dynamixel driver needs a servo mapping for every joint (joints.<joint>.servo in "
        "the head description), and the head '{}' of {} has none for some joint",
        robot.head.name(), path));
  }
}

void HwHead::Start() {
  const scene::Robot& robot = *scene_->robot();
  if (driver_kind_ == "simulated") {
    driver_ = std::make_unique<hw::SimHeadDriver>(robot.head, safety_, robot.initial_joints);
  } else {
    hw::DynamixelOptions options;
    options.baud = baud_;
    options.timeout_ms = timeout_ms_;
    options.retries = retries_;
    driver_ = hw::OpenDynamixelHead(robot.head, port_, options, safety_);
  }
  time_ = 0.0;
  reported_fault_.clear();
  if (mirror_) {
    // The virtual head starts where the device is (clamped into the limits).
    head::JointState start = driver_->Read().positions;
    for (const head::Joint joint : head::kAllJoints) {
      start[joint] =
          std::clamp(start[joint], robot.head.limits(joint).min, robot.head.limits(joint).max);
    }
    virtual_ = std::make_unique<head::Motors>(robot.head, start);
  }
}

hw::HeadDriver& HwHead::Driver() {
  if (!driver_) throw Error("the head is not started");
  return *driver_;
}

void HwHead::Send(const head::JointState& positions, const head::JointState& velocities) {
  if (virtual_) {
    virtual_->SetTarget(positions, velocities);  // clamps, or throws on NaN
    return;
  }
  const hw::CommandReport report = Driver().Command(positions, velocities);
  if (report.any()) last_limit_ = report.description;
}

JointStateMessage HwHead::HeadState() { return Joints(Driver().Read(), time_); }

JointStateMessage HwHead::Move(const JointCommand& command) {
  Send(command.positions, command.velocities);  // throws CommandRejected
  return Joints(Driver().Read(), time_);
}

void HwHead::StopHead() {
  Driver().Stop();
  if (virtual_) virtual_->Reset(virtual_->positions(), virtual_->velocities());
}

void HwHead::EmergencyStop() {
  Driver().EmergencyStop();
  if (virtual_) virtual_->Reset(virtual_->positions(), virtual_->velocities());
}

void HwHead::ClearFault() {
  Driver().ClearFault();
  reported_fault_.clear();
  // Mirror: the virtual head restarts where the device is, so that it does not jump.
  if (virtual_) virtual_->Reset(Driver().Read().positions);
}

void HwHead::Step(const runtime::StepContext& context) {
  if (command_.fresh()) {
    const JointCommand& command = command_.value();
    try {
      Send(command.positions, command.velocities);
    } catch (const Error& error) {
      // Counted by the driver and shown in the status; the loop goes on with the head safe.
      if (error.what() != last_rejection_) {
        last_rejection_ = error.what();
        log::Warn("hw.head '{}': {}", name(), last_rejection_);
      }
    }
  }
  time_ = context.time;
  if (virtual_) {
    virtual_->Step(std::max(0.0, context.time + context.dt - virtual_->time()));
    try {
      const hw::CommandReport report =
          driver_->Command(virtual_->positions(), virtual_->velocities());
      if (report.any()) last_limit_ = report.description;
    } catch (const hw::CommandRejected&) {
      // Faulty, stopped or unpowered device: the status says why.
    }
  }
  const hw::HeadStatus status = driver_->Read();
  Report(status);
  joints_.Emit(Joints(status, context.time));
  status_.Emit(Status(status, context.time));
}

void HwHead::Stop() {
  if (driver_) {
    try {
      driver_->Stop();  // leave the head holding where it is
    } catch (const std::exception&) {
    }
  }
  driver_.reset();
  virtual_.reset();
}

void HwHead::Report(const hw::HeadStatus& status) {
  if (status.fault != reported_fault_) {
    reported_fault_ = status.fault;
    if (!status.fault.empty()) {
      log::Error("hw.head '{}': FAULT: {}; the head holds until the fault is cleared", name(),
                 status.fault);
    }
  }
}

JointStateMessage HwHead::Joints(const hw::HeadStatus& status, double time) const {
  JointStateMessage out;
  out.time = time;
  if (virtual_) {
    out.positions = virtual_->positions();
    out.velocities = virtual_->velocities();
    out.targets = virtual_->targets();
    out.arrived = virtual_->Arrived(1e-4);
    out.clamped_commands = virtual_->clamped_commands();
    return out;
  }
  out.positions = status.positions;
  out.velocities = status.velocities;
  out.targets = status.targets;
  out.arrived = !status.moving;
  for (const head::Joint joint : head::kAllJoints) {
    // Servos settle within a tick or two of their goal (0.088 deg per tick).
    out.arrived = out.arrived && std::abs(status.targets[joint] - status.positions[joint]) < 0.005;
  }
  out.clamped_commands = status.limited_commands;
  return out;
}

HeadStatusMessage HwHead::Status(const hw::HeadStatus& status, double time) const {
  HeadStatusMessage out;
  out.time = time;
  out.driver = driver_ ? driver_->name() : driver_kind_;
  out.positions = status.positions;
  out.velocities = status.velocities;
  out.targets = status.targets;
  out.torque = status.torque;
  out.holding = status.holding;
  out.emergency_stopped = status.emergency_stopped;
  out.fault = status.fault;
  out.commands = status.commands;
  out.rejected_commands = status.rejected_commands;
  out.limited_commands = status.limited_commands;
  out.watchdog_trips = status.watchdog_trips;
  out.last_limit = last_limit_;
  out.mirror = mirror_;
  return out;
}

namespace {

// One camera's source from `cameras.<name>`: {uri, calibration, calibration_index, fps, loop,
// first, every}; relative paths against `base_dir`.
hw::CameraSourceSpec ReadSource(const nlohmann::json& json, const std::string& name,
                                const std::string& base_dir) {
  const std::string key = "cameras." + name;
  if (!json.is_object()) {
    throw InvalidArgument(
        fmt::format("parameter '{}': expected a map {{uri, calibration, ...}}, "
                    "got {}",
                    key, json.dump()));
  }
  hw::CameraSourceSpec spec;
  spec.name = name;
  runtime::ParamTable p;
  p.Declare("uri", &spec.uri, "the source (hw/camera_source.h)").Required();
  p.Declare("calibration", &spec.calibration, "calibration file").Path();
  p.Declare("calibration_index", &spec.calibration_index, "camera in a stereo calibration")
      .Range(0, 2);
  p.Declare("fps", &spec.fps, "pace of a file source; 0: as fast as asked")
      .Range(0.0, 1e6)
      .Unit("Hz");
  p.Declare("loop", &spec.loop, "start a file source again at its end");
  p.Declare("first", &spec.first, "frames skipped at the start").Range(0, 1000000);
  p.Declare("every", &spec.every, "every n-th frame").Range(1, 1000000);
  try {
    p.Apply(json);
  } catch (const InvalidArgument& error) {
    // "parameter 'uri': ..." -> "parameter 'cameras.left.uri': ...", and so for "unknown
    // parameter 'url'".
    std::string message = error.what();
    const std::string from = "parameter '";
    const std::size_t at = message.find(from);
    if (at != std::string::npos && at <= std::string("unknown ").size())
      message.insert(at + from.size(), key + ".");
    else
      message = key + ": " + message;
    throw InvalidArgument(message);
  }
  spec.base_dir = base_dir;
  std::string why;
  if (!spec.IsValid(&why)) throw InvalidArgument(fmt::format("parameter '{}': {}", key, why));
  return spec;
}

void SetPose(Image& image, const geometry::Pose& X_WC, const head::JointState& joints) {
  ImageMetadata& meta = image.metadata();
  const Eigen::Matrix4d m = X_WC.matrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) meta.X_WC[static_cast<std::size_t>(4 * r + c)] = m(r, c);
  }
  meta.has_joints = true;
  meta.joints = {joints.pan, joints.tilt, joints.left, joints.right};
}

}  // namespace

HwCameras::HwCameras()
    : joints_(AddInput<JointStateMessage>("joints")),
      left_(AddOutput<runtime::ImageMessage>("left")),
      right_(AddOutput<runtime::ImageMessage>("right")) {
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("cameras", &cameras_,
               "{left: SOURCE, right: SOURCE}, each SOURCE {uri (required), calibration, "
               "calibration_index 0, fps 0, loop false, first 0, every 1} as "
               "hw::CameraSourceSpec documents; paths relative to the pipeline file")
      .Required();
  DeclareParam("max_skew_s", &max_skew_s_, "the most the two time stamps of a pair may differ")
      .Range(0.0, 3600.0)
      .Unit("s");
}

void HwCameras::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  const std::string& path = scene.path;
  const nlohmann::json& cameras = cameras_;
  for (const auto& [key, value] : cameras.items()) {
    (void)value;
    if (key != "left" && key != "right") {
      throw InvalidArgument("parameter 'cameras': unknown camera '" + key +
                            "' (the head's eye cameras are left and right)");
    }
  }
  for (const char* eye : {"left", "right"}) {
    if (!cameras.contains(eye)) {
      throw InvalidArgument(std::string("parameter 'cameras': missing camera '") + eye + "'");
    }
  }
  const std::string base_dir = ResolvePath(".");
  left_spec_ = ReadSource(cameras["left"], "left", base_dir);
  right_spec_ = ReadSource(cameras["right"], "right", base_dir);
  scene_ = scene.scene;
  internal::RobotOf(*scene_, path);
}

void HwCameras::Start() {
  source_ = hw::OpenStereoSource(left_spec_, right_spec_, max_skew_s_);
  ended_ = false;
  pairs_ = 0;
  dropped_left_ = dropped_right_ = 0;
}

std::string HwCameras::Describe() const {
  return fmt::format("{} stereo pairs from {} and {}, {} + {} frames dropped (skew over {} s)",
                     pairs_, left_spec_.uri, right_spec_.uri, dropped_left_, dropped_right_,
                     max_skew_s_);
}

void HwCameras::Step(const runtime::StepContext& context) {
  if (ended_) return;
  std::optional<hw::StereoFrame> pair = source_->Grab();
  dropped_left_ = source_->dropped_left();
  dropped_right_ = source_->dropped_right();
  if (!pair) {
    ended_ = true;
    log::Info("hw.cameras '{}': the camera sources ended after {} pairs ({}, {})", name(), pairs_,
              left_spec_.uri, right_spec_.uri);
    return;
  }
  const scene::Robot& robot = *scene_->robot();
  head::JointState joints = robot.initial_joints;
  if (const JointStateMessage* state = joints_.get()) joints = state->positions;
  const head::HeadFrames frames = head::ForwardKinematics(robot.head, joints);
  // The step's time and a per-pair index, as sim.cameras stamps its frames.
  for (const auto& [image, X_WC] :
       {std::pair{pair->left, frames.X_WCamLeft}, std::pair{pair->right, frames.X_WCamRight}}) {
    SetPose(*image, X_WC, joints);
    image->metadata().time = context.time;
    image->metadata().frame_index = pairs_;
  }
  ++pairs_;
  left_.Emit(runtime::ImageMessage{pair->left});
  right_.Emit(runtime::ImageMessage{pair->right});
}

void HwCameras::Stop() { source_.reset(); }

}  // namespace saccade::components
