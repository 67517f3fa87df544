#pragma once
// DYNAMIXEL Protocol 2.0 (ROBOTIS e-Manual, "Protocol 2.0"): packets, CRC, byte stuffing, a
// streaming parser, and the X-series control table (XM430-W350, e-Manual "XM430-W350").
//
// Packet on the wire (both directions):
//   FF FF FD 00 | ID | LEN_L LEN_H | INST | [ERR] | PARAM... | CRC_L CRC_H
// LEN counts INST, ERR (status packets only), the parameters after byte stuffing, and the two
// CRC bytes. The CRC (CRC-16, polynomial 0x8005, initial value 0, not reflected) covers
// everything from the first header byte up to the last parameter, stuffing included.
// Byte stuffing: in INST..PARAM, every "FF FF FD" is followed by an extra FD, so that the
// header pattern never appears inside a packet; the receiver removes it after the CRC check.
// All multi-byte values are little-endian.
//
// Everything here is a pure function or a value type, except PacketParser (one owner).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace saccade::hw::dxl {

/// Instruction codes (the INST field).
namespace instruction {
inline constexpr uint8_t kPing = 0x01;
inline constexpr uint8_t kRead = 0x02;
inline constexpr uint8_t kWrite = 0x03;
inline constexpr uint8_t kRegWrite = 0x04;
inline constexpr uint8_t kAction = 0x05;
inline constexpr uint8_t kFactoryReset = 0x06;
inline constexpr uint8_t kReboot = 0x08;
inline constexpr uint8_t kClear = 0x10;
inline constexpr uint8_t kStatus = 0x55;  ///< the INST of every status (reply) packet
inline constexpr uint8_t kSyncRead = 0x82;
inline constexpr uint8_t kSyncWrite = 0x83;
inline constexpr uint8_t kBulkRead = 0x92;
inline constexpr uint8_t kBulkWrite = 0x93;
}  // namespace instruction

/// The ID every servo executes; servos reply to it only for Ping, Sync Read and Bulk Read.
inline constexpr uint8_t kBroadcastId = 0xFE;
/// Largest ID a servo may have (0xFD and 0xFF are never IDs: they would look like a header).
inline constexpr uint8_t kMaxId = 0xFC;

/// The ERR field of a status packet: bit 7 is the alert, bits 0..6 the error number.
namespace status_error {
inline constexpr uint8_t kResultFail = 1;        ///< failed to process the instruction
inline constexpr uint8_t kInstructionError = 2;  ///< undefined instruction, Action without RegWrite
inline constexpr uint8_t kCrcError = 3;          ///< the instruction packet's CRC did not match
inline constexpr uint8_t kDataRangeError = 4;    ///< value outside the item's min/max
inline constexpr uint8_t kDataLengthError = 5;   ///< data shorter than the item (e.g. 2 of 4 bytes)
inline constexpr uint8_t kDataLimitError = 6;    ///< value outside a limit item (position limits)
inline constexpr uint8_t kAccessError =
    7;  ///< read-only / undefined address, EEPROM with torque on
/// Set in every status while the servo has a hardware error (read HardwareErrorStatus).
inline constexpr uint8_t kAlert = 0x80;
/// The error-number bits.
inline constexpr uint8_t kNumberMask = 0x7F;
}  // namespace status_error

/// Bits of Shutdown(63) and HardwareErrorStatus(70) on X-series servos.
namespace hardware_error {
inline constexpr uint8_t kInputVoltage = 0x01;
inline constexpr uint8_t kOverheating = 0x04;
inline constexpr uint8_t kMotorEncoder = 0x08;
inline constexpr uint8_t kElectricalShock = 0x10;
inline constexpr uint8_t kOverload = 0x20;
}  // namespace hardware_error

/// "Ping", "Sync Read", ...; "instruction 0x42" for an unknown code.
std::string InstructionName(uint8_t instruction);
/// The name of the error number in the low 7 bits of a status ERR field: "no error",
/// "result fail", "instruction error", "CRC error", "data range error", "data length error",
/// "data limit error", "access error", or "error 0x09" for an undefined number. The alert
/// bit is ignored.
std::string StatusErrorName(uint8_t error);
/// The set bits of a HardwareErrorStatus value, e.g. "overheating, overload"; "none" for 0;
/// undefined bits as "bit 6".
std::string HardwareErrorNames(uint8_t bits);

/// The e-Manual's CRC-16 (polynomial 0x8005, MSB first, no final XOR) of `size` bytes,
/// continuing from `crc` (0 to start).
uint16_t Crc16(const uint8_t* data, size_t size, uint16_t crc = 0);

/// One instruction or status packet, without stuffing.
struct Packet {
  uint8_t id = 0;
  uint8_t instruction = 0;  ///< instruction::k*; instruction::kStatus for a status packet
  uint8_t error = 0;        ///< the ERR field; only meaningful in status packets
  std::vector<uint8_t> params;

  bool is_status() const { return instruction == instruction::kStatus; }
  bool operator==(const Packet&) const = default;
};

/// Size of the header (FF FF FD 00), ID and LEN fields: the bytes before INST.
inline constexpr size_t kPacketPrefixSize = 7;
/// Largest value of LEN the parser accepts by default (a generous bound on real packets).
inline constexpr size_t kDefaultMaxLength = 1024;

/// The bytes of `packet` on the wire: header, ID, LEN, INST, ERR (status packets only),
/// stuffed parameters, CRC. Throws InvalidArgument when the ID is 0xFD or 0xFF (they are
/// never IDs) or the stuffed packet does not fit LEN's 16 bits.
std::vector<uint8_t> EncodePacket(const Packet& packet);

/// Adds byte stuffing to an INST..PARAM region ("FF FF FD" -> "FF FF FD FD").
std::vector<uint8_t> StuffBytes(const std::vector<uint8_t>& region);
/// Removes byte stuffing from an INST..PARAM region (the inverse of StuffBytes).
std::vector<uint8_t> UnstuffBytes(const std::vector<uint8_t>& region);

/// Reassembles packets from a byte stream that arrives in arbitrary chunks.
///
/// It looks for the header FF FF FD 00, reads ID and LEN, waits for the whole packet,
/// checks the CRC and removes the stuffing. Bytes before a header (noise, a truncated
/// packet) are discarded; a packet whose CRC fails is counted and skipped, and the search
/// for the next header resumes right after its first byte, so a good packet that follows a
/// corrupted one is still found. A LEN below the minimum (3, or 4 for a status packet) or
/// above max_length, or an ID of 0xFD/0xFF, marks a false header, skipped likewise.
/// Not thread-safe: one reader feeds it.
class PacketParser {
 public:
  explicit PacketParser(size_t max_length = kDefaultMaxLength);

  /// Appends bytes and parses every packet they complete. Returns how many packets are
  /// now waiting in Next().
  size_t Feed(const uint8_t* data, size_t size);
  size_t Feed(const std::vector<uint8_t>& data) { return Feed(data.data(), data.size()); }
  /// The oldest complete packet, or nullopt when none is waiting.
  std::optional<Packet> Next();
  /// Number of complete packets waiting.
  size_t pending() const;
  /// Drops buffered bytes and waiting packets (the counters are kept).
  void Clear();

  /// Packets whose CRC did not match, since construction.
  int64_t crc_errors() const { return crc_errors_; }
  /// Bytes thrown away while resynchronising (noise, false headers, CRC failures).
  int64_t discarded_bytes() const { return discarded_bytes_; }
  /// Good packets parsed since construction.
  int64_t packets() const { return packets_; }

 private:
  void Parse();
  void Discard(size_t count);

  size_t max_length_;
  std::vector<uint8_t> buffer_;
  size_t start_ = 0;  // first unparsed byte of buffer_
  std::vector<Packet> ready_;
  size_t next_ = 0;  // first packet of ready_ not yet returned
  int64_t crc_errors_ = 0;
  int64_t discarded_bytes_ = 0;
  int64_t packets_ = 0;
};

// Little-endian values of 1, 2 or 4 bytes (the control table's item sizes). Every function
// throws InvalidArgument for another size.

/// Appends the low `size` bytes of `value`, least significant first.
void PutLE(std::vector<uint8_t>& out, uint32_t value, size_t size);
/// The low `size` bytes of `value`, least significant first.
std::vector<uint8_t> LEBytes(uint32_t value, size_t size);
/// The unsigned value of `size` bytes at `data`.
uint32_t GetLE(const uint8_t* data, size_t size);
/// The two's-complement value of the low `size` bytes of `value` (e.g. 0xFFFF, 2 -> -1).
int32_t SignExtend(uint32_t value, size_t size);

/// An item of a control table: where it is and how many bytes it has.
struct ControlItem {
  uint16_t address;
  uint16_t size;
  const char* name;
};

/// The X-series control table (e-Manual "XM430-W350", Protocol 2.0), items the project uses.
/// Addresses below 64 are EEPROM: writable only with Torque Enable off.
namespace table {
inline constexpr ControlItem kModelNumber{0, 2, "Model Number"};
inline constexpr ControlItem kModelInformation{2, 4, "Model Information"};
inline constexpr ControlItem kFirmwareVersion{6, 1, "Firmware Version"};
inline constexpr ControlItem kId{7, 1, "ID"};
inline constexpr ControlItem kBaudRate{8, 1, "Baud Rate"};
inline constexpr ControlItem kReturnDelayTime{9, 1, "Return Delay Time"};
inline constexpr ControlItem kDriveMode{10, 1, "Drive Mode"};
inline constexpr ControlItem kOperatingMode{11, 1, "Operating Mode"};
inline constexpr ControlItem kSecondaryId{12, 1, "Secondary ID"};
inline constexpr ControlItem kProtocolType{13, 1, "Protocol Type"};
inline constexpr ControlItem kHomingOffset{20, 4, "Homing Offset"};
inline constexpr ControlItem kMovingThreshold{24, 4, "Moving Threshold"};
inline constexpr ControlItem kTemperatureLimit{31, 1, "Temperature Limit"};
inline constexpr ControlItem kMaxVoltageLimit{32, 2, "Max Voltage Limit"};
inline constexpr ControlItem kMinVoltageLimit{34, 2, "Min Voltage Limit"};
inline constexpr ControlItem kPwmLimit{36, 2, "PWM Limit"};
inline constexpr ControlItem kCurrentLimit{38, 2, "Current Limit"};
inline constexpr ControlItem kAccelerationLimit{40, 4, "Acceleration Limit"};
inline constexpr ControlItem kVelocityLimit{44, 4, "Velocity Limit"};
inline constexpr ControlItem kMaxPositionLimit{48, 4, "Max Position Limit"};
inline constexpr ControlItem kMinPositionLimit{52, 4, "Min Position Limit"};
inline constexpr ControlItem kShutdown{63, 1, "Shutdown"};
inline constexpr ControlItem kTorqueEnable{64, 1, "Torque Enable"};
inline constexpr ControlItem kLed{65, 1, "LED"};
inline constexpr ControlItem kStatusReturnLevel{68, 1, "Status Return Level"};
inline constexpr ControlItem kRegisteredInstruction{69, 1, "Registered Instruction"};
inline constexpr ControlItem kHardwareErrorStatus{70, 1, "Hardware Error Status"};
inline constexpr ControlItem kVelocityIGain{76, 2, "Velocity I Gain"};
inline constexpr ControlItem kVelocityPGain{78, 2, "Velocity P Gain"};
inline constexpr ControlItem kPositionDGain{80, 2, "Position D Gain"};
inline constexpr ControlItem kPositionIGain{82, 2, "Position I Gain"};
inline constexpr ControlItem kPositionPGain{84, 2, "Position P Gain"};
inline constexpr ControlItem kFeedforward2ndGain{88, 2, "Feedforward 2nd Gain"};
inline constexpr ControlItem kFeedforward1stGain{90, 2, "Feedforward 1st Gain"};
inline constexpr ControlItem kBusWatchdog{98, 1, "Bus Watchdog"};
inline constexpr ControlItem kGoalPwm{100, 2, "Goal PWM"};
inline constexpr ControlItem kGoalCurrent{102, 2, "Goal Current"};
inline constexpr ControlItem kGoalVelocity{104, 4, "Goal Velocity"};
inline constexpr ControlItem kProfileAcceleration{108, 4, "Profile Acceleration"};
inline constexpr ControlItem kProfileVelocity{112, 4, "Profile Velocity"};
inline constexpr ControlItem kGoalPosition{116, 4, "Goal Position"};
inline constexpr ControlItem kRealtimeTick{120, 2, "Realtime Tick"};
inline constexpr ControlItem kMoving{122, 1, "Moving"};
inline constexpr ControlItem kMovingStatus{123, 1, "Moving Status"};
inline constexpr ControlItem kPresentPwm{124, 2, "Present PWM"};
/// Present Current on the XM series (about 2.69 mA per unit, signed).
inline constexpr ControlItem kPresentCurrent{126, 2, "Present Current"};
/// The same address on the XL430 and XC430, which report a load (0.1 % per unit) there.
inline constexpr ControlItem kPresentLoad{126, 2, "Present Load"};
inline constexpr ControlItem kPresentVelocity{128, 4, "Present Velocity"};
inline constexpr ControlItem kPresentPosition{132, 4, "Present Position"};
inline constexpr ControlItem kVelocityTrajectory{136, 4, "Velocity Trajectory"};
inline constexpr ControlItem kPositionTrajectory{140, 4, "Position Trajectory"};
inline constexpr ControlItem kPresentInputVoltage{144, 2, "Present Input Voltage"};
inline constexpr ControlItem kPresentTemperature{146, 1, "Present Temperature"};
/// First address after the items above.
inline constexpr uint16_t kEnd = 147;
/// Addresses below this one are EEPROM.
inline constexpr uint16_t kRamStart = 64;
/// The name of the item at exactly `address` (e.g. "Goal Position"), or "" if none starts there.
std::string ItemName(uint16_t address);
}  // namespace table

/// Model Number(0) of the XM430-W350.
inline constexpr uint16_t kModelXM430W350 = 1020;

// Units of the X series (e-Manual, items Present Position, Profile Velocity, Profile
// Acceleration). Positions are in ticks of the 12-bit encoder: 0..4095 is one turn and
// 2048 is the horn's middle; the conversions below do not add that offset.

/// Encoder ticks per revolution (0.088 deg per tick).
inline constexpr double kTicksPerRevolution = 4096.0;
/// rev/min per unit of Velocity Limit, Profile Velocity, Goal/Present Velocity.
inline constexpr double kRpmPerVelocityUnit = 0.229;
/// rev/min^2 per unit of Profile Acceleration (Velocity-based Profile).
inline constexpr double kRpmPerMinutePerAccelerationUnit = 214.577;

/// Ticks -> radians (ticks * 2 pi / 4096).
double TicksToRadians(double ticks);
/// Radians -> ticks, rounded to the nearest tick.
int32_t RadiansToTicks(double radians);
/// Velocity units -> rad/s.
double VelocityUnitsToRadiansPerSecond(double units);
/// rad/s -> velocity units, rounded to the nearest unit. Note that 0 in Profile Velocity
/// means "no limit but the Velocity Limit": round a small non-zero speed up to 1 if needed.
int32_t RadiansPerSecondToVelocityUnits(double radians_per_second);
/// Acceleration units -> rad/s^2.
double AccelerationUnitsToRadiansPerSecond2(double units);
/// rad/s^2 -> acceleration units, rounded to the nearest unit (0 means infinite acceleration
/// in Profile Acceleration).
int32_t RadiansPerSecond2ToAccelerationUnits(double radians_per_second2);

}  // namespace saccade::hw::dxl
