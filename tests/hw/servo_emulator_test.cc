// The emulator's control-table rules, in-process (ServoEmulator::Process, no terminal).
#include "servo_emulator/servo_emulator.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/hw/dynamixel_protocol.h"

namespace saccade::hw {
namespace {

using Bytes = std::vector<uint8_t>;
using dxl::Packet;
namespace inst = dxl::instruction;
namespace err = dxl::status_error;
namespace tbl = dxl::table;

// Sends one instruction packet and returns the status packets of the answer.
std::vector<Packet> Exchange(ServoEmulator& emulator, const Packet& instruction) {
  dxl::PacketParser parser;
  parser.Feed(emulator.Process(dxl::EncodePacket(instruction)));
  std::vector<Packet> out;
  while (auto packet = parser.Next()) out.push_back(*packet);
  EXPECT_EQ(parser.crc_errors(), 0);
  return out;
}

Packet ReadPacket(uint8_t id, uint16_t address, uint16_t length) {
  Packet p{id, inst::kRead, 0, {}};
  dxl::PutLE(p.params, address, 2);
  dxl::PutLE(p.params, length, 2);
  return p;
}

Packet WritePacket(uint8_t id, uint16_t address, const Bytes& data) {
  Packet p{id, inst::kWrite, 0, {}};
  dxl::PutLE(p.params, address, 2);
  p.params.insert(p.params.end(), data.begin(), data.end());
  return p;
}

// The status of a single-servo instruction: exactly one status packet from `id`.
Packet Status(ServoEmulator& emulator, const Packet& instruction) {
  const std::vector<Packet> answer = Exchange(emulator, instruction);
  EXPECT_EQ(answer.size(), 1u);
  if (answer.empty()) return {};
  EXPECT_EQ(answer[0].id, instruction.id);
  EXPECT_TRUE(answer[0].is_status());
  return answer[0];
}

uint8_t WriteError(ServoEmulator& emulator, uint8_t id, const dxl::ControlItem& item,
                   int64_t value) {
  return Status(emulator, WritePacket(id, item.address,
                                      dxl::LEBytes(static_cast<uint32_t>(value), item.size)))
      .error;
}

uint8_t WriteError(ServoEmulator& emulator, uint8_t id, uint16_t address, const Bytes& data) {
  return Status(emulator, WritePacket(id, address, data)).error;
}

int64_t ReadValue(ServoEmulator& emulator, uint8_t id, const dxl::ControlItem& item) {
  const Packet status = Status(emulator, ReadPacket(id, item.address, item.size));
  EXPECT_EQ(status.error & err::kNumberMask, 0) << item.name;
  EXPECT_EQ(status.params.size(), item.size) << item.name;
  if (status.params.size() != item.size) return -1;
  return dxl::GetLE(status.params.data(), item.size);
}

ServoEmulatorOptions Options(std::vector<uint8_t> ids, std::vector<int32_t> positions = {}) {
  ServoEmulatorOptions options;
  options.ids = std::move(ids);
  options.initial_positions = std::move(positions);
  return options;
}

TEST(ServoEmulatorTest, PingAnswersWithTheXm430W350ModelNumber) {
  ServoEmulator emulator(Options({1}));
  const Packet status = Status(emulator, {1, inst::kPing, 0, {}});
  EXPECT_EQ(status.error, 0);
  ASSERT_EQ(status.params.size(), 3u);
  EXPECT_EQ(dxl::GetLE(status.params.data(), 2), 1020u);
  EXPECT_TRUE(Exchange(emulator, {7, inst::kPing, 0, {}}).empty());  // nobody there
}

TEST(ServoEmulatorTest, BroadcastPingAnswersFromEveryServoInIdOrder) {
  ServoEmulator emulator(Options({4, 2, 9}));
  const std::vector<Packet> answer = Exchange(emulator, {dxl::kBroadcastId, inst::kPing, 0, {}});
  ASSERT_EQ(answer.size(), 3u);
  EXPECT_EQ(answer[0].id, 2);
  EXPECT_EQ(answer[1].id, 4);
  EXPECT_EQ(answer[2].id, 9);
  EXPECT_EQ(emulator.ids(), (std::vector<uint8_t>{2, 4, 9}));
}

TEST(ServoEmulatorTest, StartsWithTheManualsInitialValues) {
  ServoEmulator emulator(Options({3}, {1000}));
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kModelNumber), 1020);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kId), 3);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kBaudRate), 1);  // 57600
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kReturnDelayTime), 250);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kOperatingMode), 3);  // position control
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kTemperatureLimit), 80);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kVelocityLimit), 230);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kMaxPositionLimit), 4095);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kMinPositionLimit), 0);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kShutdown), 0x34);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kTorqueEnable), 0);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kStatusReturnLevel), 2);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kHardwareErrorStatus), 0);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kPresentPosition), 1000);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kGoalPosition), 1000);
  EXPECT_EQ(ReadValue(emulator, 3, tbl::kPresentTemperature), 32);
}

TEST(ServoEmulatorTest, ReadsMaySpanItemsButNotLeaveTheTable) {
  ServoEmulator emulator(Options({1}));
  const Packet whole = Status(emulator, ReadPacket(1, 0, tbl::kEnd));
  EXPECT_EQ(whole.error, 0);
  ASSERT_EQ(whole.params.size(), tbl::kEnd);
  EXPECT_EQ(dxl::GetLE(whole.params.data(), 2), 1020u);
  EXPECT_EQ(whole.params[14], 0);  // reserved
  EXPECT_EQ(Status(emulator, ReadPacket(1, 146, 2)).error, err::kAccessError);
  EXPECT_EQ(Status(emulator, ReadPacket(1, 200, 1)).error, err::kAccessError);
  EXPECT_EQ(Status(emulator, ReadPacket(1, 132, 0)).error, err::kDataLengthError);
}

TEST(ServoEmulatorTest, WritesFollowTheManualsErrorRules) {
  ServoEmulator emulator(Options({1}));
  // Part of an item.
  EXPECT_EQ(WriteError(emulator, 1, tbl::kGoalPosition.address, {0x00, 0x08}),
            err::kDataLengthError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kGoalPosition.address + 1, {0x08}), err::kDataLengthError);
  // Reserved, undefined, read-only.
  EXPECT_EQ(WriteError(emulator, 1, 14, {0}), err::kAccessError);
  EXPECT_EQ(WriteError(emulator, 1, 400, {0}), err::kAccessError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kPresentPosition, 100), err::kAccessError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kModelNumber, 1), err::kAccessError);
  // Out of the item's range.
  EXPECT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 2), err::kDataRangeError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kOperatingMode, 2), err::kDataRangeError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kVelocityLimit, 1024), err::kDataRangeError);
  // Good writes.
  EXPECT_EQ(WriteError(emulator, 1, tbl::kReturnDelayTime, 0), 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kReturnDelayTime), 0);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kLed, 1), 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kLed), 1);
}

TEST(ServoEmulatorTest, EepromIsLockedWhileTheTorqueIsOn) {
  ServoEmulator emulator(Options({1}));
  ASSERT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), 0);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kMaxPositionLimit, 3000), err::kAccessError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kReturnDelayTime, 0), err::kAccessError);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kMaxPositionLimit), 4095);
  ASSERT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 0), 0);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kMaxPositionLimit, 3000), 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kMaxPositionLimit), 3000);
}

TEST(ServoEmulatorTest, GoalOutsideThePositionLimitsIsADataLimitErrorAndChangesNothing) {
  ServoEmulator emulator(Options({1}));
  ASSERT_EQ(WriteError(emulator, 1, tbl::kMinPositionLimit, 1000), 0);
  ASSERT_EQ(WriteError(emulator, 1, tbl::kMaxPositionLimit, 3000), 0);
  ASSERT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), 0);
  ASSERT_EQ(WriteError(emulator, 1, tbl::kGoalPosition, 2500), 0);
  EXPECT_EQ(emulator.last_accepted_goal(1), 2500);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kGoalPosition, 3001), err::kDataLimitError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kGoalPosition, 999), err::kDataLimitError);
  EXPECT_EQ(emulator.last_accepted_goal(1), 2500);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kGoalPosition), 2500);
  // One write of Profile Acceleration, Profile Velocity and Goal Position (108..119) with a
  // bad goal changes none of them.
  Bytes data = dxl::LEBytes(20, 4);
  dxl::PutLE(data, 50, 4);
  dxl::PutLE(data, 3500, 4);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kProfileAcceleration.address, data), err::kDataLimitError);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kProfileVelocity), 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kProfileAcceleration), 0);
  // Goal Velocity above Velocity Limit.
  EXPECT_EQ(WriteError(emulator, 1, tbl::kGoalVelocity, 231), err::kDataLimitError);
  EXPECT_EQ(WriteError(emulator, 1, tbl::kGoalVelocity, -230), 0);
}

TEST(ServoEmulatorTest, TurningTheTorqueOnHoldsThePresentPosition) {
  ServoEmulator emulator(Options({1}, {1500}));
  ASSERT_EQ(WriteError(emulator, 1, tbl::kGoalPosition, 3000), 0);  // torque off: no motion
  EXPECT_EQ(emulator.last_accepted_goal(1), 3000);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kPresentPosition), 1500);
  ASSERT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kGoalPosition), 1500);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kMoving), 0);
}

TEST(ServoEmulatorTest, UnknownInstructionIsAnInstructionError) {
  ServoEmulator emulator(Options({1}));
  EXPECT_EQ(Status(emulator, {1, 0x30, 0, {}}).error, err::kInstructionError);
}

TEST(ServoEmulatorTest, RegWriteWaitsForAction) {
  ServoEmulator emulator(Options({1}));
  EXPECT_EQ(Status(emulator, {1, inst::kAction, 0, {}}).error, err::kInstructionError);
  Packet reg = WritePacket(1, tbl::kLed.address, {1});
  reg.instruction = inst::kRegWrite;
  EXPECT_EQ(Status(emulator, reg).error, 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kRegisteredInstruction), 1);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kLed), 0);
  EXPECT_EQ(Status(emulator, {1, inst::kAction, 0, {}}).error, 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kLed), 1);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kRegisteredInstruction), 0);
}

TEST(ServoEmulatorTest, StatusReturnLevelDecidesWhatIsAnswered) {
  ServoEmulator emulator(Options({1}));
  // The write that lowers the level is still acknowledged.
  ASSERT_EQ(WriteError(emulator, 1, tbl::kStatusReturnLevel, 1), 0);
  EXPECT_TRUE(Exchange(emulator, WritePacket(1, tbl::kLed.address, {1})).empty());
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kLed), 1);  // written all the same
  EXPECT_TRUE(Exchange(emulator, WritePacket(1, tbl::kStatusReturnLevel.address, {0})).empty());
  EXPECT_TRUE(Exchange(emulator, ReadPacket(1, tbl::kLed.address, 1)).empty());
  EXPECT_EQ(Exchange(emulator, {1, inst::kPing, 0, {}}).size(), 1u);
}

TEST(ServoEmulatorTest, BroadcastWriteIsExecutedByEveryServoWithoutAStatus) {
  ServoEmulator emulator(Options({1, 2}));
  EXPECT_TRUE(Exchange(emulator, WritePacket(dxl::kBroadcastId, tbl::kLed.address, {1})).empty());
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kLed), 1);
  EXPECT_EQ(ReadValue(emulator, 2, tbl::kLed), 1);
}

TEST(ServoEmulatorTest, SyncReadAnswersInTheRequestedOrder) {
  ServoEmulator emulator(Options({1, 2, 3}, {100, 200, 300}));
  Packet sync{dxl::kBroadcastId, inst::kSyncRead, 0, {}};
  dxl::PutLE(sync.params, tbl::kPresentPosition.address, 2);
  dxl::PutLE(sync.params, 4, 2);
  sync.params.insert(sync.params.end(), {3, 9, 1});  // 9 is not on the bus
  const std::vector<Packet> answer = Exchange(emulator, sync);
  ASSERT_EQ(answer.size(), 2u);
  EXPECT_EQ(answer[0].id, 3);
  EXPECT_EQ(dxl::GetLE(answer[0].params.data(), 4), 300u);
  EXPECT_EQ(answer[1].id, 1);
  EXPECT_EQ(dxl::GetLE(answer[1].params.data(), 4), 100u);
}

TEST(ServoEmulatorTest, SyncWriteAndBulkAccessReachEachServo) {
  ServoEmulator emulator(Options({1, 2}));
  Packet sync{dxl::kBroadcastId, inst::kSyncWrite, 0, {}};
  dxl::PutLE(sync.params, tbl::kProfileVelocity.address, 2);
  dxl::PutLE(sync.params, 4, 2);
  sync.params.push_back(1);
  dxl::PutLE(sync.params, 40, 4);
  sync.params.push_back(2);
  dxl::PutLE(sync.params, 80, 4);
  EXPECT_TRUE(Exchange(emulator, sync).empty());
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kProfileVelocity), 40);
  EXPECT_EQ(ReadValue(emulator, 2, tbl::kProfileVelocity), 80);

  Packet bulk_write{
      dxl::kBroadcastId, inst::kBulkWrite, 0, {1, 65, 0, 1, 0, 1, 2, 31, 0, 1, 0, 70}};
  EXPECT_TRUE(Exchange(emulator, bulk_write).empty());
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kLed), 1);
  EXPECT_EQ(ReadValue(emulator, 2, tbl::kTemperatureLimit), 70);

  Packet bulk_read{dxl::kBroadcastId, inst::kBulkRead, 0, {2, 146, 0, 1, 0, 1, 144, 0, 2, 0}};
  const std::vector<Packet> answer = Exchange(emulator, bulk_read);
  ASSERT_EQ(answer.size(), 2u);
  EXPECT_EQ(answer[0].id, 2);
  EXPECT_EQ(answer[0].params, Bytes{32});  // Present Temperature
  EXPECT_EQ(answer[1].id, 1);
  EXPECT_EQ(answer[1].params, (Bytes{120, 0}));  // Present Input Voltage: 12.0 V
}

TEST(ServoEmulatorTest, ShutdownErrorTurnsTheTorqueOffUntilReboot) {
  ServoEmulator emulator(Options({1}));
  ASSERT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), 0);
  ASSERT_EQ(WriteError(emulator, 1, tbl::kProfileVelocity, 50), 0);
  emulator.InjectHardwareError(1, dxl::hardware_error::kOverload);
  const Packet status = Status(emulator, ReadPacket(1, tbl::kHardwareErrorStatus.address, 1));
  EXPECT_EQ(status.error, err::kAlert);
  EXPECT_EQ(status.params, Bytes{dxl::hardware_error::kOverload});
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kTorqueEnable), 0);
  EXPECT_EQ(Status(emulator, {1, inst::kPing, 0, {}}).error, err::kAlert);  // every status
  EXPECT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), err::kAlert | err::kResultFail);
  const ServoSnapshot snapshot = emulator.Snapshot(1);
  EXPECT_FALSE(snapshot.torque);
  EXPECT_EQ(snapshot.hardware_error, dxl::hardware_error::kOverload);

  EXPECT_EQ(Status(emulator, {1, inst::kReboot, 0, {}}).error & err::kNumberMask, 0);
  EXPECT_EQ(Status(emulator, {1, inst::kPing, 0, {}}).error, 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kHardwareErrorStatus), 0);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kProfileVelocity), 0);  // RAM back to its defaults
  EXPECT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), 0);
}

TEST(ServoEmulatorTest, ErrorOutsideShutdownRaisesTheAlertButKeepsTheTorque) {
  ServoEmulator emulator(Options({1}));
  ASSERT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), 0);
  emulator.InjectHardwareError(1, dxl::hardware_error::kMotorEncoder);  // not in 0x34
  EXPECT_EQ(Status(emulator, {1, inst::kPing, 0, {}}).error, err::kAlert);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kTorqueEnable), 1);
}

TEST(ServoEmulatorTest, TemperatureAboveTheLimitIsOverheating) {
  ServoEmulator emulator(Options({1}));
  ASSERT_EQ(WriteError(emulator, 1, tbl::kTorqueEnable, 1), 0);
  emulator.SetTemperature(1, 80);  // at the limit: fine
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kHardwareErrorStatus), 0);
  emulator.SetTemperature(1, 81);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kHardwareErrorStatus), dxl::hardware_error::kOverheating);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kPresentTemperature), 81);
  EXPECT_EQ(ReadValue(emulator, 1, tbl::kTorqueEnable), 0);
}

TEST(ServoEmulatorTest, FactoryResetRestoresTheEeprom) {
  ServoEmulator emulator(Options({5}));
  ASSERT_EQ(WriteError(emulator, 5, tbl::kVelocityLimit, 100), 0);
  EXPECT_EQ(Status(emulator, {5, inst::kFactoryReset, 0, {0x01}}).error, 0);  // keep the ID
  EXPECT_EQ(ReadValue(emulator, 5, tbl::kVelocityLimit), 230);
  EXPECT_EQ(emulator.ids(), std::vector<uint8_t>{5});
}

TEST(ServoEmulatorTest, ChangingTheIdMovesTheServo) {
  ServoEmulator emulator(Options({1, 2}));
  EXPECT_EQ(WriteError(emulator, 1, tbl::kId, 7), 0);  // acknowledged from ID 1
  EXPECT_EQ(emulator.ids(), (std::vector<uint8_t>{2, 7}));
  EXPECT_EQ(ReadValue(emulator, 7, tbl::kId), 7);
  EXPECT_TRUE(Exchange(emulator, {1, inst::kPing, 0, {}}).empty());
}

TEST(ServoEmulatorTest, FaultsDropInstructionsAndCorruptStatusPackets) {
  ServoEmulator emulator(Options({1}));
  emulator.SetDropRate(1.0);
  EXPECT_TRUE(emulator.Process(dxl::EncodePacket({1, inst::kPing, 0, {}})).empty());
  emulator.SetDropRate(0.0);
  emulator.SetCorruptRate(1.0);
  dxl::PacketParser parser;
  parser.Feed(emulator.Process(dxl::EncodePacket({1, inst::kPing, 0, {}})));
  EXPECT_EQ(parser.pending(), 0u);
  EXPECT_EQ(parser.crc_errors(), 1);
  emulator.SetCorruptRate(0.0);
  emulator.SetSilent(1, true);
  EXPECT_TRUE(emulator.Process(dxl::EncodePacket({1, inst::kPing, 0, {}})).empty());
  EXPECT_TRUE(emulator.Snapshot(1).silent);
  const EmulatorCounters c = emulator.counters();
  EXPECT_EQ(c.instructions_received, 3);
  EXPECT_EQ(c.instructions_answered, 1);
  EXPECT_EQ(c.dropped, 1);
  EXPECT_EQ(c.corrupted, 1);
  EXPECT_EQ(c.status_packets, 1);
}

TEST(ServoEmulatorTest, CorruptedInstructionsAreCountedAndIgnored) {
  ServoEmulator emulator(Options({1}));
  Bytes bytes = dxl::EncodePacket({1, inst::kPing, 0, {}});
  bytes[7] ^= 0x04;
  EXPECT_TRUE(emulator.Process(bytes).empty());
  EXPECT_EQ(emulator.counters().crc_errors, 1);
  EXPECT_EQ(emulator.counters().instructions_received, 0);
}

TEST(ServoEmulatorTest, RejectsBadOptionsAndUnknownIdsNamingThem) {
  const auto message = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const InvalidArgument& e) {
      return e.what();
    }
    return "(no InvalidArgument)";
  };
  EXPECT_NE(message([] {
              ServoEmulator e(Options({1, 1}));
            }).find("ids: 1 appears twice"),
            std::string::npos);
  EXPECT_NE(message([] { ServoEmulator e(Options({253})); }).find("ids: 253"), std::string::npos);
  EXPECT_NE(message([] {
              ServoEmulator e(Options({1, 2}, {0}));
            }).find("initial_positions"),
            std::string::npos);
  ServoEmulator emulator(Options({1}));
  EXPECT_NE(message([&] { emulator.SetSilent(9, true); }).find("no servo 9"), std::string::npos);
  EXPECT_NE(message([&] { emulator.SetDropRate(1.5); }).find("rate = 1.5"), std::string::npos);
  EXPECT_NE(message([&] { emulator.SetTemperature(1, -1); }).find("-1 deg C"), std::string::npos);
}

TEST(ServoEmulatorTest, StartCreatesTheLinkAndStopRemovesIt) {
  const std::string link = (std::filesystem::temp_directory_path() /
                            ("saccade-emulator-test-" + std::to_string(::getpid())))
                               .string();
  ServoEmulator emulator(Options({1}));
  const std::string slave = emulator.Start(link);
  EXPECT_TRUE(emulator.running());
  EXPECT_EQ(emulator.slave_path(), slave);
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), slave);
  EXPECT_THROW(emulator.Start(), Error);
  emulator.Stop();
  emulator.Stop();  // idempotent
  EXPECT_FALSE(emulator.running());
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(link)));
}

}  // namespace
}  // namespace saccade::hw
