#include "saccade/hw/dynamixel_head.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <thread>
#include <utility>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/hw/dynamixel_bus.h"
#include "saccade/hw/dynamixel_protocol.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

namespace table = dxl::table;

// Bytes of a signed 32-bit item, and back (the control table is little-endian).
std::vector<uint8_t> Le32(int32_t value) { return dxl::LEBytes(static_cast<uint32_t>(value), 4); }
int32_t FromLe32(const std::vector<uint8_t>& data, std::size_t at) {
  SACCADE_ASSERT(data.size() >= at + 4, "a status packet shorter than the item it answers");
  return dxl::SignExtend(dxl::GetLE(data.data() + at, 4), 4);
}

class DynamixelHead final : public HeadDriver {
 public:
  DynamixelHead(const head::HeadModel& description, const std::string& port,
                const DynamixelOptions& options, SafetyOptions safety)
      : HeadDriver(description, safety),
        port_(port),
        bus_(port, options.baud,
             BusOptions{std::chrono::microseconds(static_cast<int64_t>(options.timeout_ms * 1000)),
                        options.retries}) {
    // Servos by joint name (the head file's servo blocks): every driven joint has one; a
    // joint the head holds may have one (it is held at its hold value) or not (fixed).
    const int n = description.num_joints();
    servos_.resize(n);
    tick_limits_.resize(n);
    profile_acceleration_.resize(n);
    std::vector<std::string> missing;
    for (int joint = 0; joint < n; ++joint) {
      const auto& servo = description.joint(joint).servo;
      if (!servo) {
        if (description.joint(joint).driven) missing.push_back(description.joint_name(joint));
        continue;
      }
      servos_[joint] = *servo;
      joints_.push_back(joint);
      ids_.push_back(static_cast<uint8_t>(servo->id));
    }
    if (!missing.empty()) {
      throw InvalidArgument(fmt::format(
          "dynamixel head: {}: the driven joint(s) {} have no servo block (joints: {{NAME: "
          "{{servo: {{id: ...}}}}}} in the head file)",
          description.source().empty() ? description.name() : description.source(),
          head::ListNames(missing)));
    }
    // Every servo answers, and none reports a hardware error.
    std::string faults;
    for (const int joint : joints_) {
      try {
        bus_.Ping(Id(joint));
      } catch (const Error& error) {
        throw HardwareError(
            port_, fmt::format("{} does not answer a ping: {}", Servo(joint), error.what()));
      }
      const uint8_t errors =
          bus_.Read(Id(joint), table::kHardwareErrorStatus.address, 1).data.at(0);
      if (errors != 0) {
        faults +=
            (faults.empty() ? "" : "; ") + Servo(joint) + ": " + dxl::HardwareErrorNames(errors);
      }
    }
    Setup();
    // A servo in a hardware error refuses the torque; the first Read() reports the fault (the
    // status packets carry the alert bit) and ClearFault() reboots it.
    if (faults.empty()) SetTorque(true);  // holds the present position
    StartWatchdog();
  }

  ~DynamixelHead() override { Shutdown(); }

  std::string name() const override { return "dynamixel on " + port_; }

 protected:
  void DoCommand(const head::JointState& positions, const head::JointState&) override {
    WriteGoals(positions);
  }

  Measurement DoRead() override {
    // Present Velocity and Present Position, 8 bytes from 128, of every servo in one packet.
    const auto replies = bus_.SyncRead(table::kPresentVelocity.address, 8, ids_);
    Measurement m;
    m.positions = description().Home();  // a joint without a servo is held there
    m.velocities = head::JointState(description().joint_names());
    m.torque = torque_;
    std::string faults;
    for (const int joint : joints_) {
      const auto it = replies.find(Id(joint));
      if (it == replies.end()) {
        throw HardwareError(port_, Servo(joint) + ": no status in the sync read");
      }
      const head::ServoMapping& servo = servos_[joint];
      const double servo_velocity =
          dxl::VelocityUnitsToRadiansPerSecond(FromLe32(it->second.data, 0));
      m.velocities[joint] = servo_velocity / (servo.direction * servo.gear_ratio);
      m.positions[joint] = TicksToJoint(servo, FromLe32(it->second.data, 4));
      if (it->second.alert()) {
        const uint8_t errors =
            bus_.Read(Id(joint), table::kHardwareErrorStatus.address, 1).data.at(0);
        faults +=
            (faults.empty() ? "" : "; ") + Servo(joint) + ": " + dxl::HardwareErrorNames(errors);
      }
    }
    if (!faults.empty()) m.fault = faults + " (the servo turned its torque off)";
    return m;
  }

  void DoTorque(bool on) override {
    // One write per servo: each is answered (a lost Sync Write would go unnoticed).
    for (const uint8_t id : ids_) bus_.WriteItem(id, table::kTorqueEnable, on ? 1 : 0);
    torque_ = on;
  }

  head::JointState DoHold() override {
    // Goal := where the servo stops when it brakes now at its profile acceleration (its
    // present position when at rest; a goal at the present position of a moving servo would
    // make it overshoot and come back). One answered write per servo that still answers: a
    // lost Sync Write would go unnoticed.
    head::JointState hold = description().Home();
    for (const int joint : joints_) {
      try {
        const std::vector<uint8_t> state =
            bus_.Read(Id(joint), table::kPresentVelocity.address, 8).data;  // velocity, position
        const double v = dxl::VelocityUnitsToRadiansPerSecond(FromLe32(state, 0));  // servo rad/s
        const double a = profile_acceleration_[joint];                              // rad/s^2
        const double braking_rad = v * std::abs(v) / (2.0 * a);
        int32_t ticks = FromLe32(state, 4) + dxl::RadiansToTicks(braking_rad);
        ticks = std::clamp(ticks, tick_limits_[joint].first, tick_limits_[joint].second);
        hold[joint] = TicksToJoint(servos_[joint], ticks);
        if (torque_) bus_.WriteItem(Id(joint), table::kGoalPosition, ticks);
      } catch (const Error&) {
        // A servo that does not answer cannot be held; the fault names it.
      }
    }
    return hold;
  }

  void DoClearFault() override {
    for (const int joint : joints_) {
      const uint8_t errors =
          bus_.Read(Id(joint), table::kHardwareErrorStatus.address, 1).data.at(0);
      if (errors == 0) continue;
      bus_.Reboot(Id(joint));
      // A rebooted servo answers again after its boot (about 0.5 s on real X-series).
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
      while (true) {
        try {
          bus_.Ping(Id(joint));
          break;
        } catch (const Error&) {
          if (std::chrono::steady_clock::now() > deadline) throw;
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
      }
      const uint8_t after = bus_.Read(Id(joint), table::kHardwareErrorStatus.address, 1).data.at(0);
      if (after != 0) {
        throw HardwareError(port_, Servo(joint) + " still reports " +
                                       dxl::HardwareErrorNames(after) + " after a reboot");
      }
    }
    Setup();  // a reboot restores the RAM area: profile velocity and acceleration
    DoTorque(true);
  }

 private:
  uint8_t Id(int joint) const { return static_cast<uint8_t>(servos_[joint].id); }
  std::string Servo(int joint) const {
    return fmt::format("servo {} ({})", Id(joint), description().joint_name(joint));
  }

  // Torque off; position mode, position limits, profile velocity and acceleration.
  void Setup() {
    DoTorque(false);
    for (const int joint : joints_) {
      const head::ServoMapping& servo = servos_[joint];
      const head::JointSettings& settings = description().joint(joint);
      // A held joint's servo stays at its hold value: its range is that one position.
      const head::JointLimits limits =
          settings.driven
              ? settings.limits
              : head::JointLimits{
                    settings.hold, settings.hold,
                    settings.limits.max_velocity > 0 ? settings.limits.max_velocity : 1.0,
                    settings.limits.max_acceleration > 0 ? settings.limits.max_acceleration : 1.0};
      int32_t a = JointToTicks(servo, limits.min);
      int32_t b = JointToTicks(servo, limits.max);
      if (a > b) std::swap(a, b);
      if (a < 0 || b > 4095) {
        throw HardwareError(port_, fmt::format("{}: the joint limits map to ticks [{}, {}], "
                                               "outside the servo's range [0, 4095]; check "
                                               "zero_offset and gear_ratio",
                                               Servo(joint), a, b));
      }
      bus_.WriteItem(Id(joint), table::kOperatingMode, 3);  // position control
      bus_.WriteItem(Id(joint), table::kMinPositionLimit, a);
      bus_.WriteItem(Id(joint), table::kMaxPositionLimit, b);
      tick_limits_[joint] = {a, b};
      const double servo_velocity = limits.max_velocity * servo.gear_ratio;
      const double servo_acceleration = limits.max_acceleration * servo.gear_ratio;
      // Round down (and at least 1: 0 means no limit): never faster than the description.
      const double velocity_unit = dxl::VelocityUnitsToRadiansPerSecond(1.0);
      const double acceleration_unit = dxl::AccelerationUnitsToRadiansPerSecond2(1.0);
      bus_.WriteItem(Id(joint), table::kProfileVelocity,
                     std::max<int64_t>(1, static_cast<int64_t>(servo_velocity / velocity_unit)));
      const int64_t acceleration_units =
          std::max<int64_t>(1, static_cast<int64_t>(servo_acceleration / acceleration_unit));
      bus_.WriteItem(Id(joint), table::kProfileAcceleration, acceleration_units);
      profile_acceleration_[joint] =
          dxl::AccelerationUnitsToRadiansPerSecond2(static_cast<double>(acceleration_units));
    }
  }

  void WriteGoals(const head::JointState& positions) {
    std::vector<std::pair<uint8_t, std::vector<uint8_t>>> data;
    for (const int joint : joints_) {
      data.push_back({Id(joint), Le32(JointToTicks(servos_[joint], positions[joint]))});
    }
    bus_.SyncWrite(table::kGoalPosition.address, 4, data);
  }

  std::string port_;
  DynamixelBus bus_;
  std::vector<head::ServoMapping> servos_;  // by joint; valid for the joints in joints_
  std::vector<int> joints_;                 // the joints with a servo, in the head's order
  std::vector<uint8_t> ids_;
  bool torque_ = false;
  std::vector<std::pair<int32_t, int32_t>> tick_limits_;  // the servos' position limits
  std::vector<double> profile_acceleration_;              // servo rad/s^2, as programmed
};

}  // namespace

int32_t JointToTicks(const head::ServoMapping& servo, double joint_angle) {
  return dxl::RadiansToTicks(servo.ServoAngle(joint_angle));
}

double TicksToJoint(const head::ServoMapping& servo, int32_t ticks) {
  return servo.JointAngle(dxl::TicksToRadians(ticks));
}

std::unique_ptr<HeadDriver> OpenDynamixelHead(const head::HeadModel& description,
                                              const std::string& port,
                                              const DynamixelOptions& options,
                                              SafetyOptions safety) {
  return std::make_unique<DynamixelHead>(description, port, options, safety);
}

}  // namespace saccade::hw
