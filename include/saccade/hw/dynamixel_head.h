#pragma once
// A head built from Dynamixel X-series servos (XM430 and kin) on one Protocol 2.0 bus over a
// serial port (issue 7): the driver of HeadDriver for real heads, and for
// saccade-servo-emulator. The head description maps each joint to its servo
// (head::ServoMapping: id, zero offset, direction, gear ratio).
//
// Opening the head: every servo must answer a ping (HardwareError names the ones that do
// not); with the torque off the driver programs each servo's own position limits from the
// joint limits (a second line of defence: the servo refuses goals beyond them), position
// control mode, and its profile velocity and acceleration from the joint's max_velocity and
// max_acceleration, so that no motion is faster than the description allows; then it turns
// the torque on and holds the present position. A servo that reports a hardware error at
// start leaves the head in the fault state (ClearFault() reboots it).
//
// Each command is one Sync Write of the four goal positions; each read one Sync Read of the
// present velocities and positions. A status with the alert bit makes the driver read the
// servo's Hardware Error Status and name it ("servo 2 (tilt): overload"); a servo that stops
// answering, or packets lost or corrupted beyond the bus's retries, are faults too (the
// HeadDriver base then holds what still answers and rejects commands until ClearFault()).
// Pursuit velocities are not sent: the goal is refreshed by every command.
#include <cstdint>
#include <memory>
#include <string>

#include "saccade/hw/head_driver.h"

namespace saccade::hw {

struct DynamixelOptions {
  int baud = 1000000;        ///< the bus's baud rate
  double timeout_ms = 20.0;  ///< for each status packet
  int retries = 2;           ///< resends after a timeout or a corrupted packet
};

/// Opens the serial port, checks and sets up the servos. Throws HardwareError naming the port
/// and the servo (and InvalidArgument when the description lacks a servo mapping).
std::unique_ptr<HeadDriver> OpenDynamixelHead(const head::HeadModel& description,
                                              const std::string& port,
                                              const DynamixelOptions& options = {},
                                              SafetyOptions safety = {});

/// Servo position ticks (4096 per turn) for a joint angle (rad), and back.
int32_t JointToTicks(const head::ServoMapping& servo, double joint_angle);
double TicksToJoint(const head::ServoMapping& servo, int32_t ticks);

}  // namespace saccade::hw
