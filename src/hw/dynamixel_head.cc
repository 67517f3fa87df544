#include "saccade/hw/dynamixel_head.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <map>
#include <numbers>
#include <thread>
#include <utility>
#include <vector>

#include "saccade/hw/dynamixel_bus.h"
#include "saccade/hw/dynamixel_protocol.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kTicksPerTurn = 4096.0;
// X-series units: velocity 0.229 rev/min, acceleration 214.577 rev/min^2.
constexpr double kVelocityUnit = 0.229 * kTwoPi / 60.0;          // rad/s
constexpr double kAccelerationUnit = 214.577 * kTwoPi / 3600.0;  // rad/s^2

// The X-series control table entries the driver uses (ROBOTIS e-manual, XM430-W350).
constexpr uint16_t kOperatingMode = 11;         // 1 byte, EEPROM: 3 = position control
constexpr uint16_t kMaxPositionLimit = 48;      // 4 bytes, EEPROM
constexpr uint16_t kMinPositionLimit = 52;      // 4 bytes, EEPROM
constexpr uint16_t kTorqueEnable = 64;          // 1 byte
constexpr uint16_t kHardwareErrorStatus = 70;   // 1 byte
constexpr uint16_t kProfileAcceleration = 108;  // 4 bytes
constexpr uint16_t kProfileVelocity = 112;      // 4 bytes
constexpr uint16_t kGoalPosition = 116;         // 4 bytes
constexpr uint16_t kPresentVelocity = 128;      // 4 bytes, followed by
                                                // PresentPosition at 132 (4 bytes)

std::vector<uint8_t> Le32(int32_t value) {
  const auto u = static_cast<uint32_t>(value);
  return {static_cast<uint8_t>(u), static_cast<uint8_t>(u >> 8), static_cast<uint8_t>(u >> 16),
          static_cast<uint8_t>(u >> 24)};
}

int32_t FromLe32(const std::vector<uint8_t>& data, std::size_t at) {
  const uint32_t u =
      static_cast<uint32_t>(data.at(at)) | static_cast<uint32_t>(data.at(at + 1)) << 8 |
      static_cast<uint32_t>(data.at(at + 2)) << 16 | static_cast<uint32_t>(data.at(at + 3)) << 24;
  return static_cast<int32_t>(u);
}

// Names the set bits of a Hardware Error Status.
std::string HardwareErrors(uint8_t bits) {
  static const std::pair<uint8_t, const char*> kBits[] = {{0x01, "input voltage error"},
                                                          {0x04, "overheating"},
                                                          {0x08, "motor encoder error"},
                                                          {0x10, "electrical shock"},
                                                          {0x20, "overload"}};
  std::string text;
  for (const auto& [bit, name] : kBits) {
    if (bits & bit) text += (text.empty() ? "" : ", ") + std::string(name);
  }
  return text.empty() ? fmt::format("hardware error 0x{:02x}", bits) : text;
}

class DynamixelHead final : public HeadDriver {
 public:
  DynamixelHead(const head::HeadDescription& description, const std::string& port,
                const DynamixelOptions& options, SafetyOptions safety)
      : HeadDriver(description, safety),
        port_(port),
        bus_(port, options.baud,
             BusOptions{std::chrono::microseconds(static_cast<int64_t>(options.timeout_ms * 1000)),
                        options.retries}) {
    for (const head::Joint joint : head::kAllJoints) {
      if (!description.servo(joint)) {
        throw InvalidArgument(
            fmt::format("dynamixel head: joint {} has no servo mapping", head::JointName(joint)));
      }
      servos_[static_cast<int>(joint)] = *description.servo(joint);
      ids_.push_back(static_cast<uint8_t>(servos_[static_cast<int>(joint)].id));
    }
    // Every servo answers, and none reports a hardware error.
    std::string faults;
    for (const head::Joint joint : head::kAllJoints) {
      try {
        bus_.Ping(Id(joint));
      } catch (const Error& error) {
        throw HardwareError(
            port_, fmt::format("{} does not answer a ping: {}", Servo(joint), error.what()));
      }
      const uint8_t errors = bus_.Read(Id(joint), kHardwareErrorStatus, 1).data.at(0);
      if (errors != 0) {
        faults += (faults.empty() ? "" : "; ") + Servo(joint) + ": " + HardwareErrors(errors);
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
    const auto replies = bus_.SyncRead(kPresentVelocity, 8, ids_);
    Measurement m;
    m.torque = torque_;
    std::string faults;
    for (const head::Joint joint : head::kAllJoints) {
      const auto it = replies.find(Id(joint));
      if (it == replies.end()) {
        throw HardwareError(port_, Servo(joint) + ": no status in the sync read");
      }
      const ServoMappingRef servo = servos_[static_cast<int>(joint)];
      const double servo_velocity = FromLe32(it->second.data, 0) * kVelocityUnit;
      m.velocities[joint] = servo_velocity / (servo.direction * servo.gear_ratio);
      m.positions[joint] = TicksToJoint(servo, FromLe32(it->second.data, 4));
      if (it->second.alert()) {
        const uint8_t errors = bus_.Read(Id(joint), kHardwareErrorStatus, 1).data.at(0);
        faults += (faults.empty() ? "" : "; ") + Servo(joint) + ": " + HardwareErrors(errors);
      }
    }
    if (!faults.empty()) m.fault = faults + " (the servo turned its torque off)";
    return m;
  }

  void DoTorque(bool on) override {
    // One write per servo: each is answered (a lost Sync Write would go unnoticed).
    for (const uint8_t id : ids_) bus_.Write(id, kTorqueEnable, {static_cast<uint8_t>(on ? 1 : 0)});
    torque_ = on;
  }

  head::JointState DoHold() override {
    // Goal := present position, for every servo that still answers (one answered write each:
    // a lost Sync Write would go unnoticed).
    head::JointState hold;
    for (const head::Joint joint : head::kAllJoints) {
      try {
        const int32_t ticks = FromLe32(bus_.Read(Id(joint), kPresentVelocity + 4, 4).data, 0);
        hold[joint] = TicksToJoint(servos_[static_cast<int>(joint)], ticks);
        if (torque_) bus_.Write(Id(joint), kGoalPosition, Le32(ticks));
      } catch (const Error&) {
        // A servo that does not answer cannot be held; the fault names it.
      }
    }
    return hold;
  }

  void DoClearFault() override {
    for (const head::Joint joint : head::kAllJoints) {
      const uint8_t errors = bus_.Read(Id(joint), kHardwareErrorStatus, 1).data.at(0);
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
      const uint8_t after = bus_.Read(Id(joint), kHardwareErrorStatus, 1).data.at(0);
      if (after != 0) {
        throw HardwareError(
            port_, Servo(joint) + " still reports " + HardwareErrors(after) + " after a reboot");
      }
    }
    Setup();  // a reboot restores the RAM area: profile velocity and acceleration
    DoTorque(true);
  }

 private:
  using ServoMappingRef = const head::ServoMapping&;

  uint8_t Id(head::Joint joint) const {
    return static_cast<uint8_t>(servos_[static_cast<int>(joint)].id);
  }
  std::string Servo(head::Joint joint) const {
    return fmt::format("servo {} ({})", Id(joint), head::JointName(joint));
  }

  // Torque off; position mode, position limits, profile velocity and acceleration.
  void Setup() {
    DoTorque(false);
    for (const head::Joint joint : head::kAllJoints) {
      const head::ServoMapping& servo = servos_[static_cast<int>(joint)];
      const head::JointLimits& limits = description().limits(joint);
      int32_t a = JointToTicks(servo, limits.min);
      int32_t b = JointToTicks(servo, limits.max);
      if (a > b) std::swap(a, b);
      if (a < 0 || b > 4095) {
        throw HardwareError(port_, fmt::format("{}: the joint limits map to ticks [{}, {}], "
                                               "outside the servo's range [0, 4095]; check "
                                               "zero_offset and gear_ratio",
                                               Servo(joint), a, b));
      }
      bus_.Write(Id(joint), kOperatingMode, {3});
      bus_.Write(Id(joint), kMinPositionLimit, Le32(a));
      bus_.Write(Id(joint), kMaxPositionLimit, Le32(b));
      const double servo_velocity = limits.max_velocity * servo.gear_ratio;
      const double servo_acceleration = limits.max_acceleration * servo.gear_ratio;
      // Round down: never faster than the description.
      bus_.Write(Id(joint), kProfileVelocity,
                 Le32(std::max<int32_t>(1, static_cast<int32_t>(servo_velocity / kVelocityUnit))));
      bus_.Write(
          Id(joint), kProfileAcceleration,
          Le32(std::max<int32_t>(1, static_cast<int32_t>(servo_acceleration / kAccelerationUnit))));
    }
  }

  void WriteGoals(const head::JointState& positions) {
    std::vector<std::pair<uint8_t, std::vector<uint8_t>>> data;
    for (const head::Joint joint : head::kAllJoints) {
      data.push_back(
          {Id(joint), Le32(JointToTicks(servos_[static_cast<int>(joint)], positions[joint]))});
    }
    bus_.SyncWrite(kGoalPosition, 4, data);
  }

  std::string port_;
  DynamixelBus bus_;
  std::array<head::ServoMapping, 4> servos_;
  std::vector<uint8_t> ids_;
  bool torque_ = false;
};

}  // namespace

int32_t JointToTicks(const head::ServoMapping& servo, double joint_angle) {
  return static_cast<int32_t>(std::lround(servo.ServoAngle(joint_angle) / kTwoPi * kTicksPerTurn));
}

double TicksToJoint(const head::ServoMapping& servo, int32_t ticks) {
  return servo.JointAngle(ticks * kTwoPi / kTicksPerTurn);
}

std::unique_ptr<HeadDriver> OpenDynamixelHead(const head::HeadDescription& description,
                                              const std::string& port,
                                              const DynamixelOptions& options,
                                              SafetyOptions safety) {
  return std::make_unique<DynamixelHead>(description, port, options, safety);
}

}  // namespace saccade::hw
