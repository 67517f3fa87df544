#include "saccade/hw/dynamixel_bus.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <set>

#include "saccade/core/error.h"

namespace saccade::hw {
namespace {

using dxl::Packet;
namespace inst = dxl::instruction;

// A status packet's size on the wire for `params` parameter bytes (no stuffing): header,
// ID, LEN, INST, ERR, parameters, CRC.
size_t StatusSize(size_t params) { return dxl::kPacketPrefixSize + 2 + params + 2; }

std::string ServoList(const std::vector<uint8_t>& ids) {
  if (ids.size() == 1) return fmt::format("servo {}", ids[0]);
  return fmt::format("servos {}", fmt::join(ids, ", "));
}

std::string Milliseconds(std::chrono::microseconds duration) {
  return fmt::format("{:g} ms", static_cast<double>(duration.count()) / 1000.0);
}

std::string DescribeAccess(const char* verb, uint16_t length, uint16_t address) {
  const std::string item = dxl::table::ItemName(address);
  return fmt::format("{} of {} byte{} at address {}{}", verb, length, length == 1 ? "" : "s",
                     address, item.empty() ? "" : " (" + item + ")");
}

void CheckId(const char* function, uint8_t id) {
  if (id > dxl::kMaxId) {
    throw InvalidArgument(fmt::format("DynamixelBus::{}: id = {}, expected a servo id in 0..{}",
                                      function, id, dxl::kMaxId));
  }
}

}  // namespace

bool BusOptions::IsValid(std::string* error) const {
  std::string why;
  if (timeout.count() <= 0) {
    why = fmt::format("timeout = {} us, expected > 0", timeout.count());
  } else if (retries < 0) {
    why = fmt::format("retries = {}, expected >= 0", retries);
  }
  if (error) *error = why;
  return why.empty();
}

BusError::BusError(const std::string& port, Kind kind, uint8_t id, const std::string& what,
                   uint8_t servo_error)
    : HardwareError(port, what), kind_(kind), id_(id), servo_error_(servo_error) {}

const char* BusErrorKindName(BusError::Kind kind) {
  switch (kind) {
    case BusError::Kind::kTimeout:
      return "timeout";
    case BusError::Kind::kCrc:
      return "CRC";
    case BusError::Kind::kServoError:
      return "servo error";
    case BusError::Kind::kProtocol:
      return "protocol";
  }
  return "?";
}

DynamixelBus::DynamixelBus(const std::string& port, int baud, BusOptions options)
    : port_([&] {
        std::string error;
        if (!options.IsValid(&error)) {
          throw InvalidArgument("DynamixelBus: " + port + ": BusOptions: " + error);
        }
        return SerialPort(port, baud);
      }()),
      options_(options) {}

std::chrono::microseconds DynamixelBus::TransferTime(size_t bytes) const {
  // 10 bits per byte (start, 8 data, stop).
  return std::chrono::microseconds(static_cast<int64_t>(bytes) * 10 * 1000000 / port_.baud() + 1);
}

void DynamixelBus::Send(const Packet& packet) {
  port_.Write(dxl::EncodePacket(packet));
  ++stats_.instructions;
}

bool DynamixelBus::FeedUntil(std::chrono::steady_clock::time_point deadline) {
  const auto left = deadline - std::chrono::steady_clock::now();
  if (left <= std::chrono::steady_clock::duration::zero()) return false;
  uint8_t buffer[512];
  const size_t n = port_.Read(
      buffer, sizeof(buffer),
      std::chrono::duration_cast<std::chrono::microseconds>(left) + std::chrono::microseconds(1));
  if (n > 0) parser_.Feed(buffer, n);
  return true;
}

void DynamixelBus::CountParserErrors(int64_t crc_before) {
  stats_.crc_errors += parser_.crc_errors() - crc_before;
  stats_.discarded_bytes = parser_.discarded_bytes();
}

DynamixelBus::Outcome DynamixelBus::Collect(const std::vector<uint8_t>& ids, int data_length,
                                            std::vector<StatusReply>* replies,
                                            std::vector<bool>* got, std::string* unexpected,
                                            const std::string& what) {
  using Clock = std::chrono::steady_clock;
  size_t waiting = 0;
  for (bool g : *got) waiting += g ? 0 : 1;
  const size_t reply_size = StatusSize(data_length < 0 ? 3 : static_cast<size_t>(data_length));
  const auto patience = options_.timeout + TransferTime(reply_size);
  auto deadline = Clock::now() + patience;
  const int64_t crc_before = parser_.crc_errors();
  bool crc_failure = false;  // a status packet failed its CRC, or a servo saw a bad instruction
  bool saw_unexpected = false;

  while (waiting > 0) {
    // Parse what is buffered before waiting for more.
    while (auto packet = parser_.Next()) {
      if (!packet->is_status()) {  // e.g. the echo of our own instruction
        ++stats_.unexpected_packets;
        continue;
      }
      ++stats_.status_packets;
      size_t index = ids.size();
      for (size_t i = 0; i < ids.size(); ++i) {
        if (ids[i] == packet->id && !(*got)[i]) index = i;
      }
      const bool fits =
          data_length < 0 || packet->params.size() == static_cast<size_t>(data_length);
      if (index == ids.size() || !fits) {
        ++stats_.unexpected_packets;
        if (!saw_unexpected) {
          *unexpected = fmt::format("a status packet from servo {} with {} data bytes", packet->id,
                                    packet->params.size());
        }
        saw_unexpected = true;
        continue;
      }
      last_error_[packet->id] = packet->error;
      if (packet->error & dxl::status_error::kAlert) ++stats_.alerts;
      const uint8_t number = packet->error & dxl::status_error::kNumberMask;
      if (number == dxl::status_error::kCrcError) {
        // The servo received a corrupted instruction: worth another try.
        ++stats_.crc_errors;
        crc_failure = true;
        continue;
      }
      if (number != 0) {
        ++stats_.servo_errors;
        throw BusError(port(), BusError::Kind::kServoError, packet->id,
                       fmt::format("servo {}: {}; request: {}", packet->id,
                                   dxl::StatusErrorName(number), what),
                       packet->error);
      }
      (*replies)[index] = StatusReply{packet->error, std::move(packet->params)};
      (*got)[index] = true;
      --waiting;
      deadline = Clock::now() + patience;  // the next servo answers after this one
    }
    if (parser_.crc_errors() != crc_before) crc_failure = true;
    if (waiting == 0) break;
    // One servo awaited and its answer was corrupted: no need to wait for the timeout.
    if (crc_failure && waiting == 1 && ids.size() == 1) break;
    if (!FeedUntil(deadline)) break;
  }
  CountParserErrors(crc_before);
  if (waiting == 0) return Outcome::kOk;
  if (crc_failure) return Outcome::kCrc;
  if (saw_unexpected) return Outcome::kProtocol;
  ++stats_.timeouts;
  return Outcome::kTimeout;
}

std::vector<StatusReply> DynamixelBus::Transact(
    const std::function<Packet(const std::vector<uint8_t>& missing)>& build,
    const std::vector<uint8_t>& ids, int data_length, const std::string& what) {
  std::vector<StatusReply> replies(ids.size());
  std::vector<bool> got(ids.size(), false);
  const int tries = options_.retries + 1;
  int crc_tries = 0;
  Outcome outcome = Outcome::kOk;
  std::string unexpected;
  std::vector<uint8_t> missing = ids;
  for (int attempt = 0; attempt < tries; ++attempt) {
    if (attempt > 0) ++stats_.retries;
    // Late answers to an earlier try would be mistaken for this one's.
    port_.DrainInput();
    parser_.Clear();
    Send(build(missing));
    if (ids.empty()) return replies;  // nobody answers (broadcast write)
    outcome = Collect(ids, data_length, &replies, &got, &unexpected, what);
    if (outcome == Outcome::kOk) return replies;
    if (outcome == Outcome::kCrc) ++crc_tries;
    missing.clear();
    for (size_t i = 0; i < ids.size(); ++i) {
      if (!got[i]) missing.push_back(ids[i]);
    }
  }
  const std::string servos = ServoList(missing);
  const std::string try_count = fmt::format("{} tr{}", tries, tries == 1 ? "y" : "ies");
  switch (outcome) {
    case Outcome::kCrc:
      throw BusError(port(), BusError::Kind::kCrc, missing.front(),
                     fmt::format("{}: the status packet failed its CRC check ({}, {} with a CRC "
                                 "error); request: {}",
                                 servos, try_count, crc_tries, what));
    case Outcome::kProtocol:
      throw BusError(port(), BusError::Kind::kProtocol, missing.front(),
                     fmt::format("{}: no matching status packet ({}), got {} instead; request: {}",
                                 servos, try_count, unexpected, what));
    default:
      throw BusError(port(), BusError::Kind::kTimeout, missing.front(),
                     fmt::format("{}: no status packet within {} ({}); request: {}", servos,
                                 Milliseconds(options_.timeout), try_count, what));
  }
}

uint16_t DynamixelBus::Ping(uint8_t id, uint8_t* firmware) {
  CheckId("Ping", id);
  const Packet packet{id, inst::kPing, 0, {}};
  const StatusReply reply = Transact([&](const auto&) { return packet; }, {id}, 3, "Ping")[0];
  if (firmware) *firmware = reply.data[2];
  return static_cast<uint16_t>(dxl::GetLE(reply.data.data(), 2));
}

std::map<uint8_t, uint16_t> DynamixelBus::BroadcastPing(std::chrono::microseconds window) {
  using Clock = std::chrono::steady_clock;
  port_.DrainInput();
  parser_.Clear();
  Send(Packet{dxl::kBroadcastId, inst::kPing, 0, {}});
  std::map<uint8_t, uint16_t> found;
  const auto deadline = Clock::now() + window;
  const int64_t crc_before = parser_.crc_errors();
  while (true) {
    while (auto packet = parser_.Next()) {
      if (!packet->is_status()) continue;
      ++stats_.status_packets;
      if (packet->params.size() != 3 || (packet->error & dxl::status_error::kNumberMask) != 0) {
        ++stats_.unexpected_packets;
        continue;
      }
      last_error_[packet->id] = packet->error;
      if (packet->error & dxl::status_error::kAlert) ++stats_.alerts;
      found[packet->id] = static_cast<uint16_t>(dxl::GetLE(packet->params.data(), 2));
    }
    if (!FeedUntil(deadline)) break;
  }
  CountParserErrors(crc_before);
  return found;
}

StatusReply DynamixelBus::Read(uint8_t id, uint16_t address, uint16_t length) {
  CheckId("Read", id);
  if (length == 0) {
    throw InvalidArgument(fmt::format(
        "DynamixelBus::Read: servo {}: length = 0 at address {}, expected > 0", id, address));
  }
  Packet packet{id, inst::kRead, 0, {}};
  dxl::PutLE(packet.params, address, 2);
  dxl::PutLE(packet.params, length, 2);
  return Transact([&](const auto&) { return packet; }, {id}, length,
                  DescribeAccess("Read", length, address))[0];
}

StatusReply DynamixelBus::Write(uint8_t id, uint16_t address, const std::vector<uint8_t>& data) {
  if (id != dxl::kBroadcastId) CheckId("Write", id);
  if (data.empty()) {
    throw InvalidArgument(
        fmt::format("DynamixelBus::Write: servo {}: no data to write at address {}", id, address));
  }
  Packet packet{id, inst::kWrite, 0, {}};
  dxl::PutLE(packet.params, address, 2);
  packet.params.insert(packet.params.end(), data.begin(), data.end());
  const std::vector<uint8_t> ids =
      id == dxl::kBroadcastId ? std::vector<uint8_t>{} : std::vector<uint8_t>{id};
  const auto length = static_cast<uint16_t>(data.size());
  auto replies = Transact([&](const auto&) { return packet; }, ids, 0,
                          DescribeAccess("Write", length, address));
  return replies.empty() ? StatusReply{} : replies[0];
}

void DynamixelBus::SyncWrite(uint16_t address, uint16_t length,
                             const std::vector<std::pair<uint8_t, std::vector<uint8_t>>>& data) {
  if (data.empty()) return;
  if (length == 0) {
    throw InvalidArgument(
        fmt::format("DynamixelBus::SyncWrite: length = 0 at address {}, expected > 0", address));
  }
  Packet packet{dxl::kBroadcastId, inst::kSyncWrite, 0, {}};
  dxl::PutLE(packet.params, address, 2);
  dxl::PutLE(packet.params, length, 2);
  std::set<uint8_t> seen;
  for (const auto& [id, bytes] : data) {
    CheckId("SyncWrite", id);
    if (!seen.insert(id).second) {
      throw InvalidArgument(
          fmt::format("DynamixelBus::SyncWrite: servo {} appears twice, expected once", id));
    }
    if (bytes.size() != length) {
      throw InvalidArgument(fmt::format(
          "DynamixelBus::SyncWrite: servo {}: {} bytes, expected {} (the length for every servo)",
          id, bytes.size(), length));
    }
    packet.params.push_back(id);
    packet.params.insert(packet.params.end(), bytes.begin(), bytes.end());
  }
  Transact([&](const auto&) { return packet; }, {}, 0,
           DescribeAccess("Sync Write", length, address));
}

std::map<uint8_t, StatusReply> DynamixelBus::SyncRead(uint16_t address, uint16_t length,
                                                      const std::vector<uint8_t>& ids) {
  if (ids.empty()) return {};
  if (length == 0) {
    throw InvalidArgument(
        fmt::format("DynamixelBus::SyncRead: length = 0 at address {}, expected > 0", address));
  }
  std::set<uint8_t> seen;
  for (uint8_t id : ids) {
    CheckId("SyncRead", id);
    if (!seen.insert(id).second) {
      throw InvalidArgument(
          fmt::format("DynamixelBus::SyncRead: servo {} appears twice, expected once", id));
    }
  }
  auto build = [&](const std::vector<uint8_t>& missing) {
    Packet packet{dxl::kBroadcastId, inst::kSyncRead, 0, {}};
    dxl::PutLE(packet.params, address, 2);
    dxl::PutLE(packet.params, length, 2);
    packet.params.insert(packet.params.end(), missing.begin(), missing.end());
    return packet;
  };
  std::vector<StatusReply> replies =
      Transact(build, ids, length, DescribeAccess("Sync Read", length, address));
  std::map<uint8_t, StatusReply> out;
  for (size_t i = 0; i < ids.size(); ++i) out[ids[i]] = std::move(replies[i]);
  return out;
}

void DynamixelBus::Reboot(uint8_t id) {
  CheckId("Reboot", id);
  const Packet packet{id, inst::kReboot, 0, {}};
  Transact([&](const auto&) { return packet; }, {id}, 0, "Reboot");
}

std::vector<uint8_t> DynamixelBus::ReadExact(uint8_t id, uint16_t address, uint16_t length) {
  return Read(id, address, length).data;  // Collect checked the length
}

uint8_t DynamixelBus::ReadU8(uint8_t id, uint16_t address) { return ReadExact(id, address, 1)[0]; }

uint16_t DynamixelBus::ReadU16(uint8_t id, uint16_t address) {
  return static_cast<uint16_t>(dxl::GetLE(ReadExact(id, address, 2).data(), 2));
}

uint32_t DynamixelBus::ReadU32(uint8_t id, uint16_t address) {
  return dxl::GetLE(ReadExact(id, address, 4).data(), 4);
}

int16_t DynamixelBus::ReadS16(uint8_t id, uint16_t address) {
  return static_cast<int16_t>(dxl::SignExtend(ReadU16(id, address), 2));
}

int32_t DynamixelBus::ReadS32(uint8_t id, uint16_t address) {
  return static_cast<int32_t>(ReadU32(id, address));
}

StatusReply DynamixelBus::WriteU8(uint8_t id, uint16_t address, uint8_t value) {
  return Write(id, address, {value});
}

StatusReply DynamixelBus::WriteU16(uint8_t id, uint16_t address, uint16_t value) {
  return Write(id, address, dxl::LEBytes(value, 2));
}

StatusReply DynamixelBus::WriteU32(uint8_t id, uint16_t address, uint32_t value) {
  return Write(id, address, dxl::LEBytes(value, 4));
}

StatusReply DynamixelBus::WriteS32(uint8_t id, uint16_t address, int32_t value) {
  return Write(id, address, dxl::LEBytes(static_cast<uint32_t>(value), 4));
}

int64_t DynamixelBus::ReadItem(uint8_t id, const dxl::ControlItem& item, bool is_signed) {
  const std::vector<uint8_t> data = ReadExact(id, item.address, item.size);
  const uint32_t raw = dxl::GetLE(data.data(), item.size);
  return is_signed ? dxl::SignExtend(raw, item.size) : static_cast<int64_t>(raw);
}

StatusReply DynamixelBus::WriteItem(uint8_t id, const dxl::ControlItem& item, int64_t value) {
  const int64_t bits = 8 * static_cast<int64_t>(item.size);
  const int64_t lowest = -(int64_t{1} << (bits - 1));
  const int64_t highest = (int64_t{1} << bits) - 1;
  if (value < lowest || value > highest) {
    throw InvalidArgument(fmt::format(
        "DynamixelBus::WriteItem: servo {}: {} = {} does not fit its {} byte{} ([{}, {}])", id,
        item.name, value, item.size, item.size == 1 ? "" : "s", lowest, highest));
  }
  return Write(id, item.address, dxl::LEBytes(static_cast<uint32_t>(value), item.size));
}

}  // namespace saccade::hw
