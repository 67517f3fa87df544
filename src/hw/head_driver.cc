#include "saccade/hw/head_driver.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <utility>

#include "saccade/core/units.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

// A joint slower than this is at rest (HeadStatus::moving).
constexpr double kMovingThreshold = 0.5 / kRadToDeg;

}  // namespace

bool CommandReport::any() const {
  for (size_t i = 0; i < position_clamped.size(); ++i) {
    if (position_clamped[i] || velocity_limited[i]) return true;
  }
  return false;
}

HeadDriver::HeadDriver(head::HeadModel description, SafetyOptions options)
    : description_(std::move(description)),
      options_(options),
      start_(std::chrono::steady_clock::now()) {
  if (!(std::isfinite(options_.watchdog_s) && options_.watchdog_s >= 0.0)) {
    throw InvalidArgument(
        fmt::format("head driver: watchdog_s must be a finite number of seconds >= 0, got {}",
                    options_.watchdog_s));
  }
}

HeadDriver::~HeadDriver() { Shutdown(); }

double HeadDriver::Now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

CommandReport HeadDriver::Command(const head::JointState& position_state,
                                  const head::JointState& velocity_state) {
  std::lock_guard lock(mutex_);
  const auto reject = [this](const std::string& why) {
    ++status_.rejected_commands;
    throw CommandRejected("head command rejected: " + why);
  };
  head::JointState positions, velocities;
  try {
    positions = description_.Arrange(position_state);
    velocities = velocity_state.empty() ? head::JointState(description_.joint_names())
                                        : description_.Arrange(velocity_state);
  } catch (const InvalidArgument& error) {
    reject(error.what());
  }
  const int n = description_.num_joints();
  for (int joint = 0; joint < n; ++joint) {
    const std::string& name = description_.joint_name(joint);
    if (!std::isfinite(positions[joint])) {
      reject(fmt::format("joint {} position is {} (not a finite number)", name, positions[joint]));
    }
    if (!std::isfinite(velocities[joint])) {
      reject(fmt::format("joint {} velocity is {} (not a finite number)", name, velocities[joint]));
    }
  }
  if (status_.emergency_stopped) reject("emergency stop (clear it first)");
  if (!status_.fault.empty()) reject("the head is faulty (" + status_.fault + "); clear the fault");
  if (!status_.torque) reject("the motors' torque is off");

  CommandReport report;
  report.sent_positions = positions;
  report.sent_velocities = velocities;
  report.position_clamped.assign(n, false);
  report.velocity_limited.assign(n, false);
  for (int joint = 0; joint < n; ++joint) {
    const int i = joint;
    const head::JointSettings& settings = description_.joint(joint);
    if (!settings.driven) {  // held: always sent its hold value, at rest
      report.sent_positions[joint] = settings.hold;
      report.sent_velocities[joint] = 0.0;
      continue;
    }
    const head::JointLimits& limits = settings.limits;
    const std::string& name = description_.joint_name(joint);
    const double p = positions[joint];
    if (p < limits.min || p > limits.max) {
      report.position_clamped[i] = true;
      report.sent_positions[joint] = std::clamp(p, limits.min, limits.max);
      report.description += fmt::format("{}{} target {:.2f} deg clamped to {:.2f} deg",
                                        report.description.empty() ? "" : "; ", name, p * kRadToDeg,
                                        report.sent_positions[joint] * kRadToDeg);
    }
    const double v = velocities[joint];
    if (std::abs(v) > limits.max_velocity) {
      report.velocity_limited[i] = true;
      report.sent_velocities[joint] = std::copysign(limits.max_velocity, v);
      report.description += fmt::format("{}{} velocity {:.1f} deg/s limited to {:.1f} deg/s",
                                        report.description.empty() ? "" : "; ", name, v * kRadToDeg,
                                        report.sent_velocities[joint] * kRadToDeg);
    }
  }
  try {
    DoCommand(report.sent_positions, report.sent_velocities);
  } catch (const Error& error) {
    EnterFault(error.what());
    ++status_.rejected_commands;
    throw CommandRejected(std::string("head command failed: ") + error.what());
  }
  ++status_.commands;
  if (report.any()) ++status_.limited_commands;
  status_.targets = report.sent_positions;
  status_.holding = false;
  last_command_time_ = Now();
  return report;
}

HeadStatus HeadDriver::Read() {
  std::lock_guard lock(mutex_);
  status_.time = Now();
  try {
    const Measurement m = DoRead();
    status_.positions = m.positions;
    status_.velocities = m.velocities;
    status_.torque = m.torque;
    if (!m.fault.empty() && m.fault != status_.fault) EnterFault(m.fault);
  } catch (const Error& error) {
    if (status_.fault.empty()) EnterFault(error.what());
  }
  status_.moving = false;
  for (int joint = 0; joint < status_.velocities.size(); ++joint) {
    status_.moving = status_.moving || std::abs(status_.velocities[joint]) > kMovingThreshold;
  }
  return status_;
}

void HeadDriver::SetTorque(bool on) {
  std::lock_guard lock(mutex_);
  DoTorque(on);
  status_.torque = on;
  if (on) {
    HoldBestEffort();
    last_command_time_ = Now();
  }
}

void HeadDriver::Stop() {
  std::lock_guard lock(mutex_);
  HoldBestEffort();
}

void HeadDriver::EmergencyStop() {
  std::lock_guard lock(mutex_);
  status_.emergency_stopped = true;
  HoldBestEffort();
}

void HeadDriver::ClearFault() {
  std::lock_guard lock(mutex_);
  DoClearFault();  // throws when the device is still faulty: the fault stays
  status_.fault.clear();
  status_.emergency_stopped = false;
  status_.torque = true;
  HoldBestEffort();
  last_command_time_ = Now();
}

void HeadDriver::EnterFault(const std::string& fault) {
  status_.fault = fault;
  HoldBestEffort();
}

void HeadDriver::HoldBestEffort() {
  try {
    status_.targets = DoHold();
  } catch (const Error& error) {
    if (status_.fault.empty()) status_.fault = error.what();
  }
}

void HeadDriver::StartWatchdog() {
  if (options_.watchdog_s <= 0.0) return;
  last_command_time_ = Now();
  watchdog_ = std::thread([this] { WatchdogLoop(); });
}

void HeadDriver::Shutdown() {
  {
    std::lock_guard lock(mutex_);
    shutting_down_ = true;
  }
  wake_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
}

void HeadDriver::WatchdogLoop() {
  const auto period = std::chrono::duration<double>(options_.watchdog_s / 5.0);
  std::unique_lock lock(mutex_);
  while (!shutting_down_) {
    wake_.wait_for(lock, period);
    if (shutting_down_) break;
    if (!status_.holding && status_.torque && Now() - last_command_time_ > options_.watchdog_s) {
      ++status_.watchdog_trips;
      status_.holding = true;
      HoldBestEffort();
    }
  }
}

SimHeadDriver::SimHeadDriver(const head::HeadModel& description, SafetyOptions options,
                             const head::JointState& initial)
    : HeadDriver(description, options),
      motors_(std::make_unique<head::Motors>(description, initial)) {
  SetTorque(true);
  StartWatchdog();
}

SimHeadDriver::~SimHeadDriver() { Shutdown(); }

void SimHeadDriver::Advance() {
  const double now = Now();
  if (now > stepped_to_) {
    if (torque_) motors_->Step(now - stepped_to_);
    stepped_to_ = now;
  }
}

void SimHeadDriver::DoCommand(const head::JointState& positions,
                              const head::JointState& velocities) {
  Advance();
  motors_->SetTarget(positions, velocities);
}

HeadDriver::Measurement SimHeadDriver::DoRead() {
  Advance();
  return {motors_->positions(), motors_->velocities(), torque_, ""};
}

void SimHeadDriver::DoTorque(bool on) {
  Advance();
  if (!on) motors_->Reset(motors_->positions());  // unpowered: the joints stay where they are
  torque_ = on;
}

head::JointState SimHeadDriver::DoHold() {
  Advance();
  // Cancels the commands: each joint brakes at its acceleration limit and stays there.
  motors_->Reset(motors_->positions(), motors_->velocities());
  return motors_->targets();
}

}  // namespace saccade::hw
