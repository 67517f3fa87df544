#pragma once
// A head's motors as a device (issue 7; seed Fig. 2: popeyeRobot): one driver interface for
// the simulated head and for real ones (dynamixel_head.h), with the safety rules enforced on
// the driver side, whatever the caller does:
//
//   - NaN or infinite values are rejected (CommandRejected naming the joint), nothing is sent;
//   - target positions outside the joint limits are clamped to them, target velocities
//     beyond max_velocity limited to it; the CommandReport says which, and the status counts
//     them (a real driver also programs the servos' own profile velocity, so that no motion
//     is faster than the head description's max_velocity);
//   - watchdog: when no command has arrived for `watchdog_s`, the head holds where it is (it
//     brakes to a stop and keeps that position) until the next command;
//   - EmergencyStop(): one call; the head holds where it is and every command is rejected
//     until ClearFault();
//   - a device fault (a servo's overload or overheating, a servo that stops answering, lost
//     or corrupted packets beyond the retries) is reported in the status and puts the head in
//     the same safe state as an emergency stop: hold what still answers, reject commands,
//     until ClearFault().
//
// Every public call is thread-safe (one mutex); the watchdog runs on its own thread.
// Backends implement the Do* hooks, which the base calls with the mutex held.

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "saccade/core/error.h"
#include "saccade/head/head_model.h"
#include "saccade/head/joint_state.h"
#include "saccade/head/motors.h"

namespace saccade::hw {

/// A command the driver refused (non-finite value, torque off, emergency stop, fault). The
/// message names the reason and, for values, the joint and value.
class CommandRejected : public Error {
 public:
  using Error::Error;
};

struct SafetyOptions {
  /// s: hold position when no command arrives for this long; 0 turns the watchdog off.
  double watchdog_s = 0.5;
};

/// What the driver changed in a command before sending it.
struct CommandReport {
  std::vector<bool> position_clamped;  ///< indexed by joint, in the head's order
  std::vector<bool> velocity_limited;
  head::JointState sent_positions;   ///< rad, as sent
  head::JointState sent_velocities;  ///< rad/s, as sent
  bool any() const;
  /// "" when nothing was changed; else e.g. "pan target 120.0 deg clamped to 90.0 deg".
  std::string description;
};

/// The head as its driver sees it.
struct HeadStatus {
  double time = 0.0;            ///< s since the driver opened (steady clock)
  head::JointState positions;   ///< rad, measured
  head::JointState velocities;  ///< rad/s, measured
  head::JointState targets;     ///< rad, the last targets sent (the hold position when held)
  bool torque = false;          ///< motors powered
  bool holding = false;         ///< the watchdog stopped the head: no command for watchdog_s
  bool emergency_stopped = false;
  std::string fault;     ///< a device fault, "" when none
  bool moving = false;   ///< any joint faster than 0.5 deg/s
  int64_t commands = 0;  ///< accepted commands
  int64_t rejected_commands = 0;
  int64_t limited_commands = 0;  ///< accepted, but clamped or velocity-limited
  int64_t watchdog_trips = 0;
  /// Commands may be sent: torque on, no emergency stop, no fault.
  bool ready() const { return torque && !emergency_stopped && fault.empty(); }
};

/// Base of every head driver: the interface and its safety rules.
class HeadDriver {
 public:
  /// Throws InvalidArgument when watchdog_s is negative or not finite.
  HeadDriver(head::HeadModel head, SafetyOptions options);
  virtual ~HeadDriver();
  HeadDriver(const HeadDriver&) = delete;
  HeadDriver& operator=(const HeadDriver&) = delete;

  /// What kind of head ("simulated", "dynamixel on /dev/ttyUSB0").
  virtual std::string name() const = 0;
  const head::HeadModel& description() const { return description_; }
  const SafetyOptions& options() const { return options_; }

  /// Sends joint targets (rad): a saccade, or smooth pursuit when `velocities` (rad/s) are not
  /// all zero; empty: zero). By joint name: a state in another order is arranged in the
  /// head's; a joint the head holds (not driven) is sent its hold value. Checked, clamped and
  /// limited as above. Throws CommandRejected (nothing sent) for non-finite values, unknown or
  /// missing joints, with the torque off, after an emergency stop or a fault.
  CommandReport Command(const head::JointState& positions, const head::JointState& velocities = {});
  /// Reads the joints. Never throws for a device fault: the status reports it (and the head
  /// goes to its safe state).
  HeadStatus Read();
  /// Powers the motors on or off. Turning them on holds the present position.
  void SetTorque(bool on);
  /// Brakes every joint and holds where it stops (not latched: the next command moves).
  void Stop();
  /// Holds where it is and rejects every command until ClearFault().
  void EmergencyStop();
  /// Clears an emergency stop and faults (a real driver reboots the faulty servos and turns
  /// their torque back on); the head holds its present position. Throws HardwareError when
  /// the device is still faulty.
  void ClearFault();

 protected:
  /// What a backend measures.
  struct Measurement {
    head::JointState positions;
    head::JointState velocities;
    bool torque = false;
    std::string fault;  ///< "" when the device is fine
  };
  /// Backend hooks, called with the mutex held. They may throw saccade::Error for a device
  /// error; the base turns it into a fault.
  virtual void DoCommand(const head::JointState& positions, const head::JointState& velocities) = 0;
  virtual Measurement DoRead() = 0;
  virtual void DoTorque(bool on) = 0;
  /// Brake and hold where the joints stop (best effort on a faulty device); returns the hold
  /// positions (rad).
  virtual head::JointState DoHold() = 0;
  virtual void DoClearFault() = 0;

  /// Seconds on the driver's clock (steady, since construction).
  double Now() const;
  /// Derived classes start the watchdog at the end of their constructor and must call
  /// Shutdown() first thing in their destructor (the watchdog calls the hooks).
  void StartWatchdog();
  void Shutdown();

 private:
  void EnterFault(const std::string& fault);  // mutex held
  void HoldBestEffort();                      // mutex held
  void WatchdogLoop();

  head::HeadModel description_;
  SafetyOptions options_;
  std::chrono::steady_clock::time_point start_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::thread watchdog_;
  bool shutting_down_ = false;

  double last_command_time_ = 0.0;
  HeadStatus status_;
};

/// The simulated head as a driver: head::Motors (saccades and pursuit under the velocity and
/// acceleration limits) advanced by the driver's steady clock. The reference implementation
/// of the interface, and the virtual head an operator moves in mirror mode.
class SimHeadDriver final : public HeadDriver {
 public:
  /// The head at rest at `initial` (rad), torque on. Throws InvalidArgument for positions
  /// outside the limits.
  explicit SimHeadDriver(const head::HeadModel& description, SafetyOptions options = {},
                         const head::JointState& initial = {});
  ~SimHeadDriver() override;
  std::string name() const override { return "simulated"; }

 protected:
  void DoCommand(const head::JointState& positions, const head::JointState& velocities) override;
  Measurement DoRead() override;
  void DoTorque(bool on) override;
  head::JointState DoHold() override;
  void DoClearFault() override {}

 private:
  void Advance();
  std::unique_ptr<head::Motors> motors_;
  double stepped_to_ = 0.0;
  bool torque_ = true;
};

}  // namespace saccade::hw
