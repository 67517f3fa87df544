#include "saccade/components/hw_head.h"

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
  if (driver_kind_ == "dynamixel") {
    std::vector<std::string> missing;
    for (int j = 0; j < robot.head.num_joints(); ++j) {
      if (robot.head.joint(j).driven && !robot.head.joint(j).servo) {
        missing.push_back(robot.head.joint_name(j));
      }
    }
    if (!missing.empty()) {
      throw InvalidArgument(fmt::format(
          "the dynamixel driver needs a servo mapping for every driven joint (joints.<joint>.servo "
          "in the head file), and the head '{}' of {} has none for: {}",
          robot.head.name(), path, head::ListNames(missing)));
    }
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
    head::JointState start = robot.head.Arrange(driver_->Read().positions);
    for (int joint = 0; joint < start.size(); ++joint) {
      const head::JointSettings& s = robot.head.joint(joint);
      start[joint] = s.driven ? std::clamp(start[joint], s.limits.min, s.limits.max) : s.hold;
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
  if (scene_ && scene_->robot()) {
    out.head = std::shared_ptr<const head::HeadModel>(scene_, &scene_->robot()->head);
  }
  if (virtual_) {
    out.positions = virtual_->positions();
    out.velocities = virtual_->velocities();
    out.targets = virtual_->targets();
    out.target_velocities = virtual_->target_velocities();
    out.arrived = virtual_->Arrived(1e-4);
    out.clamped_commands = virtual_->clamped_commands();
    return out;
  }
  out.positions = status.positions;
  out.velocities = status.velocities;
  out.targets = status.targets;
  out.arrived = !status.moving;
  for (int joint = 0; joint < status.targets.size() && joint < status.positions.size(); ++joint) {
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

}  // namespace saccade::components
