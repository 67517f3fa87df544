#pragma once
// An emulated bus of X-series servos (XM430-W350, model 1020) speaking DYNAMIXEL Protocol 2.0
// on a pseudo-terminal: for the tests, and for users without the robot
// (tools/servo_emulator/main.cc: saccade-servo-emulator). A tool, not part of the production
// hw library (DESIGN.md): the library saccade_servo_emulator, linked by the program and the
// tests.
//
// Start() opens a PseudoTerminal and serves its master from a background thread; programs
// open the slave (or the symbolic link) as their serial port, at any baud rate. Process()
// runs the same servos on bytes in-process, without a terminal.
//
// Each servo has the X-series control table (dxl::table, addresses 0..146) with the
// e-Manual's initial values, except Velocity Limit 230 (about 53 rev/min; the factory value
// depends on the firmware). Rules, as the e-Manual states them:
//   - Instructions: Ping (broadcast: every servo answers, in ID order), Read, Write,
//     Reg Write, Action, Factory Reset, Reboot, Clear, Sync Read, Sync Write, Bulk Read,
//     Bulk Write; another code gets instruction error (2). Broadcast instructions are
//     executed without a status, except Ping, Sync Read and Bulk Read. Status Return Level
//     (68) is honoured (0: Ping only, 1: also reads, 2: all). A servo answers from the ID
//     and at the level it had when the instruction arrived (a write of ID or Status Return
//     Level is acknowledged as before it).
//   - Reads may span several items (and the reserved bytes between them, read as 0) within
//     addresses 0..146; beyond: access error (7).
//   - Writes must cover whole items: part of an item is a data length error (5); a
//     reserved or undefined address, a read-only item, or an EEPROM item (address < 64)
//     while Torque Enable is 1 is an access error (7); a value outside the item's range is a
//     data range error (4); Goal Position outside [Min Position Limit, Max Position Limit]
//     (Position Control Mode) or Goal Velocity above Velocity Limit is a data limit error
//     (6). A write that fails changes nothing.
//   - Turning the torque on holds the present position (Goal Position := Present Position).
//   - Motion: with the torque on, Present Position moves to Goal Position along the
//     time-optimal trapezoid (head::JointProfile) under Profile Velocity (0: Velocity
//     Limit; never above it) and Profile Acceleration (0: infinite). Present Velocity,
//     Moving, the trajectories and Realtime Tick follow; the state is evaluated from
//     std::chrono::steady_clock at each instruction and every update period. Only position
//     control is emulated (Operating Mode 3, or 4 without the position limits); in other
//     modes the servo holds still.
//   - Hardware errors (InjectHardwareError, or Present Temperature above Temperature Limit
//     -> overheating) set Hardware Error Status (70) and the alert bit (0x80) of every
//     status; a bit that is also in Shutdown (63) turns the torque off, and writing Torque
//     Enable 1 then fails with result fail (1). Only Reboot clears them (and the RAM area).
//   - Return Delay Time is not emulated (servos answer at once); a corrupted instruction
//     packet is ignored (no CRC error status).
//
// Fault injection, for testing the bus and the drivers: dropped instruction packets,
// corrupted status packets (one byte flipped, so the CRC fails), silent servos, hardware
// errors, temperatures. Random faults come from a seeded generator.
//
// Thread-safety: every public function may be called from any thread while the emulator
// runs (one mutex guards the servos); Start() and Stop() from one controlling thread.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "saccade/hw/dynamixel_protocol.h"
#include "saccade/hw/serial_port.h"

namespace saccade::hw {

/// The emulated servos and faults at start.
struct ServoEmulatorOptions {
  /// Servo IDs (0..252, distinct).
  std::vector<uint8_t> ids{1, 2, 3, 4};
  /// Initial Present Position of each servo (ticks, 0..4095), in the order of `ids`; empty:
  /// 2048 (the middle) for every servo.
  std::vector<int32_t> initial_positions;
  /// Probability that an instruction packet is ignored, in [0, 1].
  double drop_rate = 0.0;
  /// Probability that a status packet gets one byte flipped, in [0, 1].
  double corrupt_rate = 0.0;
  /// Seed of the fault generator.
  uint64_t seed = 1;
  /// How often the background thread advances the servos between instructions (> 0).
  std::chrono::microseconds update_period{10000};

  /// Whether the options are usable; says why not in `error` (naming the field).
  bool IsValid(std::string* error = nullptr) const;
};

/// One servo's state, for tests and status lines.
struct ServoSnapshot {
  uint8_t id = 0;
  int32_t position = 0;         ///< Present Position (ticks)
  int32_t goal = 0;             ///< Goal Position (ticks)
  int32_t velocity = 0;         ///< Present Velocity (units of 0.229 rev/min)
  double velocity_ticks = 0.0;  ///< the exact velocity (ticks/s)
  bool torque = false;          ///< Torque Enable
  bool moving = false;          ///< Moving
  uint8_t hardware_error = 0;   ///< Hardware Error Status (dxl::hardware_error bits)
  int temperature = 0;          ///< Present Temperature (deg C)
  bool silent = false;          ///< whether it ignores the bus (SetSilent)
};

/// What the emulator has seen and done since it was constructed.
struct EmulatorCounters {
  int64_t instructions_received = 0;  ///< good instruction packets parsed
  int64_t instructions_answered = 0;  ///< of those, the ones that got a status packet
  int64_t status_packets = 0;         ///< status packets sent (corrupted ones included)
  int64_t dropped = 0;                ///< instruction packets ignored by the drop rate
  int64_t corrupted = 0;              ///< status packets corrupted on purpose
  int64_t crc_errors = 0;             ///< instruction packets that failed their CRC check
};

/// A bus of emulated X-series servos.
class ServoEmulator {
 public:
  /// Throws InvalidArgument naming the field for invalid options.
  explicit ServoEmulator(ServoEmulatorOptions options = {});
  /// Stops the thread (Stop()).
  ~ServoEmulator();
  ServoEmulator(const ServoEmulator&) = delete;
  ServoEmulator& operator=(const ServoEmulator&) = delete;

  /// Creates the pseudo-terminal (with a symbolic link to its slave at `symlink` unless
  /// empty) and starts serving it. Returns the slave's path, e.g. "/dev/pts/3". Throws
  /// HardwareError when the terminal or link cannot be made, Error when already running.
  std::string Start(const std::string& symlink = "");
  /// Stops serving, joins the thread, closes the terminal and removes the link. Idempotent.
  void Stop();
  bool running() const { return thread_.joinable(); }
  /// The slave's path while running, else "".
  std::string slave_path() const;

  /// Feeds instruction bytes (any chunking) to the servos in-process and returns the bytes
  /// of the status packets they answer, as they would appear on the wire. Independent of
  /// the terminal (its own parser); faults apply.
  std::vector<uint8_t> Process(const uint8_t* data, size_t size);
  std::vector<uint8_t> Process(const std::vector<uint8_t>& data) {
    return Process(data.data(), data.size());
  }

  // Fault injection. Ids not on the bus throw InvalidArgument naming the id.

  /// Probability in [0, 1] that an instruction packet is ignored (as if lost on the wire).
  void SetDropRate(double rate);
  /// Probability in [0, 1] that a status packet gets one byte flipped after INST.
  void SetCorruptRate(double rate);
  /// A silent servo ignores every packet, broadcast included (as if unplugged).
  void SetSilent(uint8_t id, bool silent);
  /// Raises hardware errors (dxl::hardware_error bits, e.g. kOverload): see the rules above.
  void InjectHardwareError(uint8_t id, uint8_t bits);
  /// Sets Present Temperature (deg C, 0..255); above Temperature Limit it raises overheating.
  void SetTemperature(uint8_t id, int celsius);

  // Inspection.

  /// The servo's state now. Throws InvalidArgument for an unknown id.
  ServoSnapshot Snapshot(uint8_t id) const;
  /// Every servo's state now, in ID order.
  std::vector<ServoSnapshot> Snapshots() const;
  EmulatorCounters counters() const;
  /// The last Goal Position the servo accepted (ticks), or nullopt if none yet. Throws
  /// InvalidArgument for an unknown id.
  std::optional<int32_t> last_accepted_goal(uint8_t id) const;
  /// The servos' ids, in ID order.
  std::vector<uint8_t> ids() const;

 private:
  struct Servo;
  using Clock = std::chrono::steady_clock;

  // Everything below runs with mutex_ held.
  std::vector<uint8_t> HandleLocked(const dxl::Packet& packet, Clock::time_point now);
  Servo* FindLocked(uint8_t id);
  const Servo* FindLocked(uint8_t id) const;
  Servo& CheckedLocked(const char* function, uint8_t id);
  const Servo& CheckedLocked(const char* function, uint8_t id) const;
  // Advances a servo's state to `now` (also a copy of one: touches nothing else).
  void UpdateLocked(Servo& servo, Clock::time_point now) const;
  void UpdateAllLocked(Clock::time_point now);
  void RaiseLocked(Servo& servo, uint8_t bits, Clock::time_point now) const;
  void ReplanLocked(Servo& servo, Clock::time_point now);
  void ResetRamLocked(Servo& servo, Clock::time_point now);
  uint8_t ValidateWriteLocked(const Servo& servo, uint16_t address,
                              const std::vector<uint8_t>& data) const;
  uint8_t WriteLocked(Servo& servo, uint16_t address, const std::vector<uint8_t>& data,
                      Clock::time_point now);
  uint8_t ReadLocked(const Servo& servo, uint16_t address, uint16_t length,
                     std::vector<uint8_t>* data) const;
  // Appends the status of `servo` (alert bit and corruption included) sent as `id`.
  void AppendStatusLocked(std::vector<uint8_t>& out, const Servo& servo, uint8_t id, uint8_t error,
                          std::vector<uint8_t> params);
  ServoSnapshot SnapshotLocked(const Servo& servo) const;
  std::vector<uint8_t> FeedLocked(dxl::PacketParser& parser, const uint8_t* data, size_t size);

  void Serve();  // the thread

  mutable std::mutex mutex_;
  ServoEmulatorOptions options_;
  std::vector<std::unique_ptr<Servo>> servos_;  // ID order
  EmulatorCounters counters_;
  std::mt19937_64 rng_;
  Clock::time_point start_time_;
  dxl::PacketParser in_process_parser_;

  std::unique_ptr<PseudoTerminal> terminal_;
  std::thread thread_;
  int wake_fds_[2] = {-1, -1};  // a pipe: Stop() writes, the thread wakes up
};

}  // namespace saccade::hw
