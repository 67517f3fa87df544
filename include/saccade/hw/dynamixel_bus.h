#pragma once
// A DYNAMIXEL Protocol 2.0 bus: one serial port, many servos (dynamixel_protocol.h).
//
// Every call sends one instruction packet and waits for the status packet(s) it asks for.
// A try fails when no matching status packet arrives within BusOptions::timeout (plus the
// time the reply takes on the wire at the port's baud rate), when the status packet fails
// its CRC check, or when the servo reports that the instruction failed its CRC (status error
// 3). A failed try is retried (the input is drained, the instruction sent again) up to
// BusOptions::retries times; after the last try the call throws BusError (kTimeout, kCrc or
// kProtocol). A status packet from another servo or for another request (a late reply to an
// earlier try) is skipped and counted. A status whose error number (ERR & 0x7F) is neither 0
// nor 3 throws BusError kServoError naming the error at once: the servo has answered, and the
// same instruction would fail again.
//
// The alert bit (ERR bit 7) never throws: the servo has a hardware error (overload,
// overheating, ...) and has probably turned its torque off. It is returned in StatusReply,
// remembered per servo (alert(id)) and counted; read HardwareErrorStatus to see which.
//
// The servos must answer every instruction (Status Return Level 2, the default).
//
// A port that fails (adapter unplugged, emulator stopped) throws HardwareError from
// SerialPort, not BusError: retrying cannot help.
//
// Not thread-safe: one thread owns the bus (a driver's control loop). A call blocks for at
// most (retries + 1) * (timeout + transfer time), per servo for a Sync Read.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "saccade/hw/dynamixel_protocol.h"
#include "saccade/hw/hw_error.h"
#include "saccade/hw/serial_port.h"

namespace saccade::hw {

/// How patiently the bus waits for servos.
struct BusOptions {
  /// How long to wait for a status packet after sending (or after the previous status packet
  /// of a Sync Read), on top of its transfer time. 20 ms by default; a servo's Return Delay
  /// Time (default 500 us) must fit in it.
  std::chrono::microseconds timeout{20000};
  /// Extra tries after a timeout or CRC failure (0: one try only).
  int retries = 2;

  /// Whether the options are usable (timeout > 0, retries >= 0); says why not in `error`.
  bool IsValid(std::string* error = nullptr) const;
};

/// A bus call that failed: no answer, a corrupted answer, a servo's error, a wrong answer.
class BusError : public HardwareError {
 public:
  enum class Kind {
    kTimeout,     ///< no status packet within the timeout, after every try
    kCrc,         ///< the status packets failed their CRC (or the servo saw a corrupted
                  ///< instruction), after every try
    kServoError,  ///< the servo answered with an error number (servo_error())
    kProtocol,    ///< the answers came from another servo or did not fit the request
  };

  /// The message is "<port>: <what>"; `what` starts with "servo <id>: " (or "servos 3, 4: ").
  BusError(const std::string& port, Kind kind, uint8_t id, const std::string& what,
           uint8_t servo_error = 0);

  Kind kind() const { return kind_; }
  /// The servo concerned (the first one missing, for a Sync Read).
  uint8_t id() const { return id_; }
  /// The status packet's ERR field for kServoError (alert bit included), else 0.
  uint8_t servo_error() const { return servo_error_; }

 private:
  Kind kind_;
  uint8_t id_;
  uint8_t servo_error_;
};

/// "timeout", "CRC", "servo error", "protocol".
const char* BusErrorKindName(BusError::Kind kind);

/// Counters since the bus was opened.
struct BusStats {
  int64_t instructions = 0;        ///< instruction packets sent, retries included
  int64_t status_packets = 0;      ///< good status packets received (skipped ones included)
  int64_t timeouts = 0;            ///< tries that ended without the expected status packet
  int64_t crc_errors = 0;          ///< status packets that failed the CRC check here, plus
                                   ///< servos reporting a corrupted instruction (error 3)
  int64_t retries = 0;             ///< instructions sent again after a failed try
  int64_t unexpected_packets = 0;  ///< status packets skipped (another servo, another request)
  int64_t servo_errors = 0;        ///< status packets with an error number (thrown)
  int64_t alerts = 0;              ///< status packets with the alert bit set
  int64_t discarded_bytes = 0;     ///< received bytes that were not part of a good packet
};

/// A servo's answer.
struct StatusReply {
  uint8_t error = 0;          ///< the ERR field; only the alert bit can be set in a returned reply
  std::vector<uint8_t> data;  ///< the parameters (the bytes read; empty for a Write)
  /// Bit 0x80: the servo has a hardware error; read HardwareErrorStatus to see which.
  bool alert() const { return (error & dxl::status_error::kAlert) != 0; }
};

/// A serial port with DYNAMIXEL Protocol 2.0 servos on it.
class DynamixelBus {
 public:
  /// Opens `port` at `baud` (see SerialPort). Throws HardwareError as SerialPort does, and
  /// InvalidArgument naming the field for invalid options.
  DynamixelBus(const std::string& port, int baud, BusOptions options = {});

  /// Pings servo `id` (0..252); returns its model number (1020 for an XM430-W350) and, when
  /// `firmware` is given, stores its firmware version there.
  uint16_t Ping(uint8_t id, uint8_t* firmware = nullptr);
  /// Pings every servo (broadcast) and returns {id: model number} of those that answered
  /// within `window`. X-series servos answer in ID order, one after the other; the default
  /// window is DynamixelSDK's (3 ms per possible ID + 16 ms). No answer: an empty map.
  std::map<uint8_t, uint16_t> BroadcastPing(
      std::chrono::microseconds window = std::chrono::microseconds(3000 * 253 + 16000));

  /// Reads `length` bytes from `address` of servo `id`.
  StatusReply Read(uint8_t id, uint16_t address, uint16_t length);
  /// Writes `data` at `address` of servo `id` and waits for its status. For the broadcast
  /// id (0xFE) every servo writes and none answers: the reply is empty.
  StatusReply Write(uint8_t id, uint16_t address, const std::vector<uint8_t>& data);
  /// Writes `length` bytes at `address` of several servos with one packet: `data` holds
  /// (id, bytes) pairs, each with exactly `length` bytes. No servo answers a Sync Write, so
  /// a lost packet goes unnoticed: read back what matters. Throws InvalidArgument for a
  /// wrong length or a repeated id; does nothing for an empty `data`.
  void SyncWrite(uint16_t address, uint16_t length,
                 const std::vector<std::pair<uint8_t, std::vector<uint8_t>>>& data);
  /// Reads `length` bytes at `address` of several servos with one packet; they answer in
  /// the order of `ids`. Retries only the servos that did not answer. Returns {id: reply}
  /// for every id. Throws InvalidArgument for a repeated id or the broadcast id; does
  /// nothing for empty `ids`.
  std::map<uint8_t, StatusReply> SyncRead(uint16_t address, uint16_t length,
                                          const std::vector<uint8_t>& ids);
  /// Reboots servo `id`: torque off, hardware errors cleared, RAM back to its defaults. A
  /// real servo needs a moment before it answers again after its status packet.
  void Reboot(uint8_t id);

  // Typed access to one item (little-endian, as the control table stores it).
  uint8_t ReadU8(uint8_t id, uint16_t address);
  uint16_t ReadU16(uint8_t id, uint16_t address);
  uint32_t ReadU32(uint8_t id, uint16_t address);
  int16_t ReadS16(uint8_t id, uint16_t address);
  int32_t ReadS32(uint8_t id, uint16_t address);
  StatusReply WriteU8(uint8_t id, uint16_t address, uint8_t value);
  StatusReply WriteU16(uint8_t id, uint16_t address, uint16_t value);
  StatusReply WriteU32(uint8_t id, uint16_t address, uint32_t value);
  StatusReply WriteS32(uint8_t id, uint16_t address, int32_t value);
  /// The item's value, sign-extended for 1- and 2-byte items only when `is_signed`.
  int64_t ReadItem(uint8_t id, const dxl::ControlItem& item, bool is_signed = false);
  /// Writes `value` into the item's size (its low bytes).
  StatusReply WriteItem(uint8_t id, const dxl::ControlItem& item, int64_t value);

  /// Whether the last status packet of servo `id` had the alert bit set.
  bool alert(uint8_t id) const { return last_error_[id] & dxl::status_error::kAlert; }
  const BusStats& stats() const { return stats_; }
  const BusOptions& options() const { return options_; }
  /// The serial port's path.
  const std::string& port() const { return port_.path(); }

 private:
  // How a try ended.
  enum class Outcome { kOk, kTimeout, kCrc, kProtocol };

  // Sends the instruction that `build` makes for the servos still to answer, and collects
  // one status packet per id of `ids` (none for an empty list), with retries. `data_length`
  // is the expected parameter count (-1: any). `what` describes the request for messages.
  // Returns the replies in the order of `ids`.
  std::vector<StatusReply> Transact(
      const std::function<dxl::Packet(const std::vector<uint8_t>& missing)>& build,
      const std::vector<uint8_t>& ids, int data_length, const std::string& what);
  // One try: waits for the status packets of the ids i with !(*got)[i]; fills replies[i]
  // and got[i] for each one received. `unexpected` describes the first packet skipped.
  // Throws BusError kServoError for a status with an error number (but CRC error).
  Outcome Collect(const std::vector<uint8_t>& ids, int data_length,
                  std::vector<StatusReply>* replies, std::vector<bool>* got,
                  std::string* unexpected, const std::string& what);
  void Send(const dxl::Packet& packet);
  // Feeds the parser what the port delivers until `deadline` (one read); false once it passed.
  bool FeedUntil(std::chrono::steady_clock::time_point deadline);
  // Adds the parser's CRC errors since `crc_before` and its discarded bytes to the statistics.
  void CountParserErrors(int64_t crc_before);
  std::chrono::microseconds TransferTime(size_t bytes) const;
  std::vector<uint8_t> ReadExact(uint8_t id, uint16_t address, uint16_t length);

  SerialPort port_;
  BusOptions options_;
  dxl::PacketParser parser_;
  BusStats stats_;
  uint8_t last_error_[256] = {};
};

}  // namespace saccade::hw
