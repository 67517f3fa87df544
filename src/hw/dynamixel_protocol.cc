#include "saccade/hw/dynamixel_protocol.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "saccade/core/error.h"

namespace saccade::hw::dxl {
namespace {

constexpr uint8_t kHeader[4] = {0xFF, 0xFF, 0xFD, 0x00};

// The CRC-16 lookup table for polynomial 0x8005 (MSB first), built at compile time.
constexpr std::array<uint16_t, 256> MakeCrcTable() {
  std::array<uint16_t, 256> table{};
  for (int i = 0; i < 256; ++i) {
    uint16_t crc = static_cast<uint16_t>(i << 8);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x8000) ? static_cast<uint16_t>((crc << 1) ^ 0x8005)
                           : static_cast<uint16_t>(crc << 1);
    }
    table[i] = crc;
  }
  return table;
}
constexpr std::array<uint16_t, 256> kCrcTable = MakeCrcTable();

void CheckSize(const char* function, size_t size) {
  if (size != 1 && size != 2 && size != 4) {
    throw InvalidArgument(
        fmt::format("dxl::{}: size = {} bytes, expected 1, 2 or 4", function, size));
  }
}

}  // namespace

std::string InstructionName(uint8_t code) {
  switch (code) {
    case instruction::kPing:
      return "Ping";
    case instruction::kRead:
      return "Read";
    case instruction::kWrite:
      return "Write";
    case instruction::kRegWrite:
      return "Reg Write";
    case instruction::kAction:
      return "Action";
    case instruction::kFactoryReset:
      return "Factory Reset";
    case instruction::kReboot:
      return "Reboot";
    case instruction::kClear:
      return "Clear";
    case instruction::kStatus:
      return "Status";
    case instruction::kSyncRead:
      return "Sync Read";
    case instruction::kSyncWrite:
      return "Sync Write";
    case instruction::kBulkRead:
      return "Bulk Read";
    case instruction::kBulkWrite:
      return "Bulk Write";
    default:
      return fmt::format("instruction 0x{:02X}", code);
  }
}

std::string StatusErrorName(uint8_t error) {
  switch (error & status_error::kNumberMask) {
    case 0:
      return "no error";
    case status_error::kResultFail:
      return "result fail";
    case status_error::kInstructionError:
      return "instruction error";
    case status_error::kCrcError:
      return "CRC error";
    case status_error::kDataRangeError:
      return "data range error";
    case status_error::kDataLengthError:
      return "data length error";
    case status_error::kDataLimitError:
      return "data limit error";
    case status_error::kAccessError:
      return "access error";
    default:
      return fmt::format("error 0x{:02X}", error & status_error::kNumberMask);
  }
}

std::string HardwareErrorNames(uint8_t bits) {
  if (bits == 0) return "none";
  std::string names;
  for (int bit = 0; bit < 8; ++bit) {
    const uint8_t mask = static_cast<uint8_t>(1u << bit);
    if (!(bits & mask)) continue;
    const char* name = nullptr;
    switch (mask) {
      case hardware_error::kInputVoltage:
        name = "input voltage";
        break;
      case hardware_error::kOverheating:
        name = "overheating";
        break;
      case hardware_error::kMotorEncoder:
        name = "motor encoder";
        break;
      case hardware_error::kElectricalShock:
        name = "electrical shock";
        break;
      case hardware_error::kOverload:
        name = "overload";
        break;
      default:
        break;
    }
    if (!names.empty()) names += ", ";
    names += name ? std::string(name) : fmt::format("bit {}", bit);
  }
  return names;
}

uint16_t Crc16(const uint8_t* data, size_t size, uint16_t crc) {
  for (size_t i = 0; i < size; ++i) {
    const uint8_t index = static_cast<uint8_t>((crc >> 8) ^ data[i]);
    crc = static_cast<uint16_t>((crc << 8) ^ kCrcTable[index]);
  }
  return crc;
}

std::vector<uint8_t> StuffBytes(const std::vector<uint8_t>& region) {
  std::vector<uint8_t> out;
  out.reserve(region.size() + region.size() / 3 + 1);
  for (uint8_t byte : region) {
    out.push_back(byte);
    const size_t n = out.size();
    if (n >= 3 && out[n - 3] == 0xFF && out[n - 2] == 0xFF && out[n - 1] == 0xFD) {
      out.push_back(0xFD);
    }
  }
  return out;
}

std::vector<uint8_t> UnstuffBytes(const std::vector<uint8_t>& region) {
  std::vector<uint8_t> out;
  out.reserve(region.size());
  for (size_t i = 0; i < region.size(); ++i) {
    out.push_back(region[i]);
    const size_t n = out.size();
    if (n >= 3 && out[n - 3] == 0xFF && out[n - 2] == 0xFF && out[n - 1] == 0xFD &&
        i + 1 < region.size() && region[i + 1] == 0xFD) {
      ++i;  // the stuffed FD
    }
  }
  return out;
}

std::vector<uint8_t> EncodePacket(const Packet& packet) {
  if (packet.id == 0xFD || packet.id == 0xFF) {
    throw InvalidArgument(fmt::format(
        "dxl::EncodePacket: id = 0x{:02X}, expected 0..0xFC or 0xFE (broadcast)", packet.id));
  }
  std::vector<uint8_t> region;
  region.reserve(packet.params.size() + 2);
  region.push_back(packet.instruction);
  if (packet.is_status()) region.push_back(packet.error);
  region.insert(region.end(), packet.params.begin(), packet.params.end());
  const std::vector<uint8_t> stuffed = StuffBytes(region);
  const size_t length = stuffed.size() + 2;  // + CRC
  if (length > 0xFFFF) {
    throw InvalidArgument(fmt::format(
        "dxl::EncodePacket: {} with {} parameter bytes does not fit a packet (LEN = {} > 65535)",
        InstructionName(packet.instruction), packet.params.size(), length));
  }
  std::vector<uint8_t> out(std::begin(kHeader), std::end(kHeader));
  out.reserve(kPacketPrefixSize + length);
  out.push_back(packet.id);
  PutLE(out, static_cast<uint32_t>(length), 2);
  out.insert(out.end(), stuffed.begin(), stuffed.end());
  PutLE(out, Crc16(out.data(), out.size()), 2);
  return out;
}

PacketParser::PacketParser(size_t max_length) : max_length_(max_length) {}

size_t PacketParser::Feed(const uint8_t* data, size_t size) {
  // Compact first: the consumed prefix and the packets already handed out.
  if (start_ > 0 && start_ * 2 >= buffer_.size()) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  if (next_ > 0 && next_ == ready_.size()) {
    ready_.clear();
    next_ = 0;
  }
  buffer_.insert(buffer_.end(), data, data + size);
  Parse();
  return pending();
}

std::optional<Packet> PacketParser::Next() {
  if (next_ >= ready_.size()) return std::nullopt;
  Packet packet = std::move(ready_[next_++]);
  if (next_ == ready_.size()) {
    ready_.clear();
    next_ = 0;
  }
  return packet;
}

size_t PacketParser::pending() const { return ready_.size() - next_; }

void PacketParser::Clear() {
  buffer_.clear();
  start_ = 0;
  ready_.clear();
  next_ = 0;
}

void PacketParser::Discard(size_t count) {
  start_ += count;
  discarded_bytes_ += static_cast<int64_t>(count);
}

void PacketParser::Parse() {
  while (true) {
    const size_t available = buffer_.size() - start_;
    const uint8_t* p = buffer_.data() + start_;
    // Find the header FF FF FD 00; keep a tail that may be its beginning.
    size_t offset = 0;
    bool found = false;
    while (offset + 4 <= available) {
      if (p[offset] == 0xFF && p[offset + 1] == 0xFF && p[offset + 2] == 0xFD &&
          p[offset + 3] == 0x00) {
        found = true;
        break;
      }
      ++offset;
    }
    if (!found) {
      // At most 3 trailing bytes can start a header still to come.
      size_t keep = 0;
      for (size_t k = std::min<size_t>(3, available); k > 0; --k) {
        if (std::equal(p + available - k, p + available, kHeader)) {
          keep = k;
          break;
        }
      }
      Discard(available - keep);
      return;
    }
    if (offset > 0) Discard(offset);
    const uint8_t* packet = buffer_.data() + start_;
    const size_t have = buffer_.size() - start_;
    if (have < kPacketPrefixSize) return;
    const uint8_t id = packet[4];
    const size_t length = GetLE(packet + 5, 2);
    if (id == 0xFD || id == 0xFF || length < 3 || length > max_length_) {
      Discard(1);  // a false header
      continue;
    }
    const size_t total = kPacketPrefixSize + length;
    if (have < total) return;
    const uint16_t crc = Crc16(packet, total - 2);
    if (crc != GetLE(packet + total - 2, 2)) {
      ++crc_errors_;
      Discard(1);  // resynchronise from the next byte: a good packet may hide in there
      continue;
    }
    const std::vector<uint8_t> region =
        UnstuffBytes(std::vector<uint8_t>(packet + kPacketPrefixSize, packet + total - 2));
    Packet result;
    result.id = id;
    result.instruction = region[0];
    size_t params_start = 1;
    if (result.is_status()) {
      if (region.size() < 2) {  // a status packet without its ERR field
        Discard(1);
        continue;
      }
      result.error = region[1];
      params_start = 2;
    }
    result.params.assign(region.begin() + static_cast<std::ptrdiff_t>(params_start), region.end());
    ready_.push_back(std::move(result));
    ++packets_;
    start_ += total;
  }
}

void PutLE(std::vector<uint8_t>& out, uint32_t value, size_t size) {
  CheckSize("PutLE", size);
  for (size_t i = 0; i < size; ++i) out.push_back(static_cast<uint8_t>(value >> (8 * i)));
}

std::vector<uint8_t> LEBytes(uint32_t value, size_t size) {
  std::vector<uint8_t> out;
  PutLE(out, value, size);
  return out;
}

uint32_t GetLE(const uint8_t* data, size_t size) {
  CheckSize("GetLE", size);
  uint32_t value = 0;
  for (size_t i = 0; i < size; ++i) value |= static_cast<uint32_t>(data[i]) << (8 * i);
  return value;
}

int32_t SignExtend(uint32_t value, size_t size) {
  CheckSize("SignExtend", size);
  if (size == 4) return static_cast<int32_t>(value);
  const unsigned bits = static_cast<unsigned>(8 * size);
  const uint32_t mask = (1u << bits) - 1;
  value &= mask;
  const uint32_t sign = 1u << (bits - 1);
  return (value & sign) ? static_cast<int32_t>(value) - static_cast<int32_t>(1u << bits)
                        : static_cast<int32_t>(value);
}

namespace table {
std::string ItemName(uint16_t address) {
  static constexpr ControlItem kItems[] = {kModelNumber,
                                           kModelInformation,
                                           kFirmwareVersion,
                                           kId,
                                           kBaudRate,
                                           kReturnDelayTime,
                                           kDriveMode,
                                           kOperatingMode,
                                           kSecondaryId,
                                           kProtocolType,
                                           kHomingOffset,
                                           kMovingThreshold,
                                           kTemperatureLimit,
                                           kMaxVoltageLimit,
                                           kMinVoltageLimit,
                                           kPwmLimit,
                                           kCurrentLimit,
                                           kAccelerationLimit,
                                           kVelocityLimit,
                                           kMaxPositionLimit,
                                           kMinPositionLimit,
                                           kShutdown,
                                           kTorqueEnable,
                                           kLed,
                                           kStatusReturnLevel,
                                           kRegisteredInstruction,
                                           kHardwareErrorStatus,
                                           kVelocityIGain,
                                           kVelocityPGain,
                                           kPositionDGain,
                                           kPositionIGain,
                                           kPositionPGain,
                                           kFeedforward2ndGain,
                                           kFeedforward1stGain,
                                           kBusWatchdog,
                                           kGoalPwm,
                                           kGoalCurrent,
                                           kGoalVelocity,
                                           kProfileAcceleration,
                                           kProfileVelocity,
                                           kGoalPosition,
                                           kRealtimeTick,
                                           kMoving,
                                           kMovingStatus,
                                           kPresentPwm,
                                           kPresentCurrent,
                                           kPresentVelocity,
                                           kPresentPosition,
                                           kVelocityTrajectory,
                                           kPositionTrajectory,
                                           kPresentInputVoltage,
                                           kPresentTemperature};
  for (const ControlItem& item : kItems) {
    if (item.address == address) return item.name;
  }
  return "";
}
}  // namespace table

namespace {
constexpr double kRadiansPerTick = 2.0 * std::numbers::pi / kTicksPerRevolution;
// rev/min -> rad/s, and rev/min^2 -> rad/s^2.
constexpr double kRadPerSecPerRpm = 2.0 * std::numbers::pi / 60.0;
constexpr double kRadPerSec2PerRpmPerMin = 2.0 * std::numbers::pi / 3600.0;

int32_t RoundToInt32(const char* function, double value) {
  const double rounded = std::round(value);
  if (!std::isfinite(rounded) || rounded < -2147483648.0 || rounded > 2147483647.0) {
    throw InvalidArgument(
        fmt::format("dxl::{}: {} does not fit a 32-bit control table value", function, value));
  }
  return static_cast<int32_t>(rounded);
}
}  // namespace

double TicksToRadians(double ticks) { return ticks * kRadiansPerTick; }

int32_t RadiansToTicks(double radians) {
  return RoundToInt32("RadiansToTicks", radians / kRadiansPerTick);
}

double VelocityUnitsToRadiansPerSecond(double units) {
  return units * kRpmPerVelocityUnit * kRadPerSecPerRpm;
}

int32_t RadiansPerSecondToVelocityUnits(double radians_per_second) {
  return RoundToInt32("RadiansPerSecondToVelocityUnits",
                      radians_per_second / (kRpmPerVelocityUnit * kRadPerSecPerRpm));
}

double AccelerationUnitsToRadiansPerSecond2(double units) {
  return units * kRpmPerMinutePerAccelerationUnit * kRadPerSec2PerRpmPerMin;
}

int32_t RadiansPerSecond2ToAccelerationUnits(double radians_per_second2) {
  return RoundToInt32(
      "RadiansPerSecond2ToAccelerationUnits",
      radians_per_second2 / (kRpmPerMinutePerAccelerationUnit * kRadPerSec2PerRpmPerMin));
}

}  // namespace saccade::hw::dxl
