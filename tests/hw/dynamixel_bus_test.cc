// DynamixelBus over a real pseudo-terminal, against the emulated servos (or a scripted one).
#include "saccade/hw/dynamixel_bus.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "saccade/core/error.h"
#include "servo_emulator/servo_emulator.h"

namespace saccade::hw {
namespace {

using Bytes = std::vector<uint8_t>;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
namespace tbl = dxl::table;
namespace err = dxl::status_error;

constexpr int kBaud = 57600;
// Generous for the tests that expect answers (it costs nothing when they come): an
// AddressSanitizer build on a busy 2-core machine can be slow to schedule the emulator.
constexpr milliseconds kPatientTimeout{100};
// Short, for the tests that expect silence.
constexpr milliseconds kShortTimeout{5};

ServoEmulatorOptions Servos(std::vector<int32_t> positions = {}) {
  ServoEmulatorOptions options;
  options.ids = {1, 2, 3, 4};
  options.initial_positions = std::move(positions);
  options.update_period = milliseconds(5);
  return options;
}

// An emulator on a pseudo-terminal and a bus on its slave.
struct Rig {
  explicit Rig(ServoEmulatorOptions options = Servos(),
               BusOptions bus_options = {kPatientTimeout, 2})
      : emulator(options), path(emulator.Start()), bus(path, kBaud, bus_options) {}
  ServoEmulator emulator;
  std::string path;
  DynamixelBus bus;
};

BusError CatchBusError(const std::function<void()>& f) {
  try {
    f();
  } catch (const BusError& e) {
    return e;
  }
  ADD_FAILURE() << "expected a BusError";
  return BusError("", BusError::Kind::kProtocol, 0, "(none)");
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(DynamixelBusTest, PingReturnsTheModelNumberOfEveryServo) {
  Rig rig;
  for (uint8_t id : {1, 2, 3, 4}) {
    uint8_t firmware = 0;
    EXPECT_EQ(rig.bus.Ping(id, &firmware), 1020) << int(id);
    EXPECT_GT(firmware, 0);
  }
  EXPECT_EQ(rig.bus.stats().instructions, 4);
  EXPECT_EQ(rig.bus.stats().status_packets, 4);
  EXPECT_EQ(rig.bus.port(), rig.path);
}

TEST(DynamixelBusTest, BroadcastPingFindsEveryServo) {
  Rig rig;
  const std::map<uint8_t, uint16_t> found = rig.bus.BroadcastPing(milliseconds(100));
  EXPECT_EQ(found, (std::map<uint8_t, uint16_t>{{1, 1020}, {2, 1020}, {3, 1020}, {4, 1020}}));
}

TEST(DynamixelBusTest, ReadsAndWritesItems) {
  Rig rig(Servos({1000, 2000, 3000, 4000}));
  EXPECT_EQ(rig.bus.ReadU16(3, tbl::kModelNumber.address), 1020);
  EXPECT_EQ(rig.bus.ReadS32(3, tbl::kPresentPosition.address), 3000);
  EXPECT_EQ(rig.bus.ReadU8(2, tbl::kLed.address), 0);
  const StatusReply reply = rig.bus.WriteU8(2, tbl::kLed.address, 1);
  EXPECT_FALSE(reply.alert());
  EXPECT_TRUE(reply.data.empty());
  EXPECT_EQ(rig.bus.ReadU8(2, tbl::kLed.address), 1);
  EXPECT_EQ(rig.bus.ReadU8(1, tbl::kLed.address), 0);  // only servo 2
  rig.bus.WriteU32(4, tbl::kProfileVelocity.address, 123);
  EXPECT_EQ(rig.bus.ReadItem(4, tbl::kProfileVelocity), 123);
  rig.bus.WriteItem(4, tbl::kProfileAcceleration, 45);
  EXPECT_EQ(rig.bus.ReadU32(4, tbl::kProfileAcceleration.address), 45u);
  const StatusReply raw = rig.bus.Read(1, tbl::kPresentPosition.address, 4);
  EXPECT_EQ(raw.data, dxl::LEBytes(1000, 4));
  // Signed values: Goal Velocity -100.
  rig.bus.WriteS32(1, tbl::kGoalVelocity.address, -100);
  EXPECT_EQ(rig.bus.ReadS32(1, tbl::kGoalVelocity.address), -100);
  EXPECT_EQ(rig.bus.ReadItem(1, tbl::kGoalVelocity, /*is_signed=*/true), -100);
}

TEST(DynamixelBusTest, SyncWriteAndSyncReadFourServos) {
  Rig rig;
  const std::vector<uint8_t> ids = {1, 2, 3, 4};
  rig.bus.SyncWrite(tbl::kTorqueEnable.address, 1, {{1, {1}}, {2, {1}}, {3, {1}}, {4, {1}}});
  const std::vector<int32_t> goals = {1024, 1536, 2560, 3072};
  std::vector<std::pair<uint8_t, Bytes>> data;
  for (size_t i = 0; i < ids.size(); ++i) {
    data.emplace_back(ids[i], dxl::LEBytes(static_cast<uint32_t>(goals[i]), 4));
  }
  rig.bus.SyncWrite(tbl::kGoalPosition.address, 4, data);
  const std::map<uint8_t, StatusReply> read = rig.bus.SyncRead(tbl::kGoalPosition.address, 4, ids);
  ASSERT_EQ(read.size(), 4u);
  for (size_t i = 0; i < ids.size(); ++i) {
    const StatusReply& reply = read.at(ids[i]);
    ASSERT_EQ(reply.data.size(), 4u);
    EXPECT_EQ(static_cast<int32_t>(dxl::GetLE(reply.data.data(), 4)), goals[i]);
    EXPECT_EQ(rig.emulator.last_accepted_goal(ids[i]), goals[i]);
    EXPECT_TRUE(rig.emulator.Snapshot(ids[i]).torque);
  }
  // Two instructions without an answer, one Sync Read with four.
  EXPECT_EQ(rig.bus.stats().instructions, 3);
  EXPECT_EQ(rig.bus.stats().status_packets, 4);
}

TEST(DynamixelBusTest, GoalOutsideThePositionLimitsIsANamedDataLimitError) {
  Rig rig;
  rig.bus.WriteU32(1, tbl::kMaxPositionLimit.address, 3000);  // EEPROM: torque off
  rig.bus.WriteU8(1, tbl::kTorqueEnable.address, 1);
  rig.bus.WriteS32(1, tbl::kGoalPosition.address, 2500);
  const BusError e = CatchBusError([&] { rig.bus.WriteS32(1, tbl::kGoalPosition.address, 3500); });
  EXPECT_EQ(e.kind(), BusError::Kind::kServoError);
  EXPECT_EQ(e.id(), 1);
  EXPECT_EQ(e.servo_error() & err::kNumberMask, err::kDataLimitError);
  EXPECT_EQ(e.device(), rig.path);
  EXPECT_TRUE(Contains(e.what(), rig.path + ": servo 1: data limit error")) << e.what();
  EXPECT_TRUE(Contains(e.what(), "Goal Position")) << e.what();
  // Nothing changed: no retry either (the servo answered).
  EXPECT_EQ(rig.emulator.last_accepted_goal(1), 2500);
  EXPECT_EQ(rig.bus.ReadS32(1, tbl::kGoalPosition.address), 2500);
  EXPECT_EQ(rig.bus.stats().retries, 0);
  EXPECT_EQ(rig.bus.stats().servo_errors, 1);
}

TEST(DynamixelBusTest, EepromWriteWithTheTorqueOnIsANamedAccessError) {
  Rig rig;
  rig.bus.WriteU8(2, tbl::kTorqueEnable.address, 1);
  const BusError e = CatchBusError([&] { rig.bus.WriteU8(2, tbl::kReturnDelayTime.address, 0); });
  EXPECT_EQ(e.kind(), BusError::Kind::kServoError);
  EXPECT_EQ(e.servo_error(), err::kAccessError);
  EXPECT_TRUE(Contains(e.what(), ": servo 2: access error")) << e.what();
  rig.bus.WriteU8(2, tbl::kTorqueEnable.address, 0);
  rig.bus.WriteU8(2, tbl::kReturnDelayTime.address, 0);
  EXPECT_EQ(rig.bus.ReadU8(2, tbl::kReturnDelayTime.address), 0);
}

TEST(DynamixelBusTest, LostInstructionsTimeOutNamingTheServoAndPortAfterRetries) {
  Rig rig(Servos(), {kShortTimeout, 2});
  rig.emulator.SetDropRate(1.0);
  const BusError e = CatchBusError([&] { rig.bus.Read(2, tbl::kPresentPosition.address, 4); });
  EXPECT_EQ(e.kind(), BusError::Kind::kTimeout);
  EXPECT_EQ(e.id(), 2);
  EXPECT_EQ(std::string(e.what()),
            rig.path +
                ": servo 2: no status packet within 5 ms (3 tries); request: Read of 4 bytes at "
                "address 132 (Present Position)");
  const BusStats& s = rig.bus.stats();
  EXPECT_EQ(s.instructions, 3);
  EXPECT_EQ(s.retries, 2);
  EXPECT_EQ(s.timeouts, 3);
  EXPECT_EQ(s.status_packets, 0);
  EXPECT_EQ(rig.emulator.counters().dropped, 3);
}

TEST(DynamixelBusTest, LossyBusStillSucceedsThanksToRetries) {
  ServoEmulatorOptions options = Servos();
  options.drop_rate = 0.3;
  options.corrupt_rate = 0.3;
  options.seed = 42;
  // A try fails with probability 1 - 0.7 * 0.7 = 0.51 for one servo; 21 tries fail together
  // with probability 0.51^21 < 1e-6.
  Rig rig(options, {milliseconds(10), 20});
  rig.bus.SyncWrite(tbl::kTorqueEnable.address, 1, {});  // nothing to do
  for (uint8_t id : {1, 2, 3, 4}) rig.bus.WriteU8(id, tbl::kLed.address, 1);
  for (int i = 0; i < 20; ++i) {
    const uint8_t id = static_cast<uint8_t>(1 + i % 4);
    const uint32_t velocity = static_cast<uint32_t>(10 + i);
    rig.bus.WriteU32(id, tbl::kProfileVelocity.address, velocity);
    EXPECT_EQ(rig.bus.ReadU32(id, tbl::kProfileVelocity.address), velocity);
    const auto leds = rig.bus.SyncRead(tbl::kLed.address, 1, {1, 2, 3, 4});
    ASSERT_EQ(leds.size(), 4u);
    for (const auto& [servo, reply] : leds) EXPECT_EQ(reply.data, Bytes{1}) << int(servo);
  }
  const BusStats& s = rig.bus.stats();
  EXPECT_GT(s.retries, 0);
  EXPECT_GT(s.crc_errors, 0);
  EXPECT_GT(s.timeouts, 0);
  const EmulatorCounters c = rig.emulator.counters();
  EXPECT_GT(c.dropped, 0);
  EXPECT_GT(c.corrupted, 0);
  EXPECT_EQ(s.instructions, c.instructions_received);
}

TEST(DynamixelBusTest, SilentServoTimesOutWhileTheOthersAnswer) {
  Rig rig(Servos(), {kShortTimeout, 1});
  rig.emulator.SetSilent(3, true);
  const BusError ping = CatchBusError([&] { rig.bus.Ping(3); });
  EXPECT_EQ(ping.kind(), BusError::Kind::kTimeout);
  EXPECT_EQ(ping.id(), 3);
  EXPECT_TRUE(Contains(ping.what(), ": servo 3: no status packet within 5 ms (2 tries)"))
      << ping.what();
  EXPECT_EQ(rig.bus.Ping(4), 1020);
  const BusError sync = CatchBusError([&] {
    rig.bus.SyncRead(tbl::kPresentPosition.address, 4, {1, 2, 3, 4});
  });
  EXPECT_EQ(sync.kind(), BusError::Kind::kTimeout);
  EXPECT_EQ(sync.id(), 3);
  EXPECT_TRUE(Contains(sync.what(), ": servo 3: no status packet")) << sync.what();
  EXPECT_TRUE(Contains(sync.what(), "Sync Read")) << sync.what();
  rig.emulator.SetSilent(3, false);
  EXPECT_EQ(rig.bus.Ping(3), 1020);
}

TEST(DynamixelBusTest, OverloadRaisesTheAlertTurnsTheTorqueOffAndRebootClearsIt) {
  Rig rig;
  rig.bus.WriteU8(2, tbl::kTorqueEnable.address, 1);
  EXPECT_FALSE(rig.bus.alert(2));
  rig.emulator.InjectHardwareError(2, dxl::hardware_error::kOverload);
  const StatusReply reply = rig.bus.Read(2, tbl::kHardwareErrorStatus.address, 1);
  EXPECT_TRUE(reply.alert());
  EXPECT_TRUE(rig.bus.alert(2));
  EXPECT_FALSE(rig.bus.alert(1));
  ASSERT_EQ(reply.data.size(), 1u);
  EXPECT_EQ(dxl::HardwareErrorNames(reply.data[0]), "overload");
  EXPECT_EQ(rig.bus.ReadU8(2, tbl::kTorqueEnable.address), 0);
  EXPECT_GE(rig.bus.stats().alerts, 2);
  // The torque cannot come back before a reboot.
  const BusError e = CatchBusError([&] { rig.bus.WriteU8(2, tbl::kTorqueEnable.address, 1); });
  EXPECT_EQ(e.servo_error(), err::kAlert | err::kResultFail);
  EXPECT_TRUE(Contains(e.what(), "servo 2: result fail")) << e.what();

  rig.bus.Reboot(2);
  EXPECT_EQ(rig.bus.ReadU8(2, tbl::kHardwareErrorStatus.address), 0);
  EXPECT_FALSE(rig.bus.alert(2));
  rig.bus.WriteU8(2, tbl::kTorqueEnable.address, 1);
  EXPECT_EQ(rig.bus.ReadU8(2, tbl::kTorqueEnable.address), 1);
}

TEST(DynamixelBusTest, OverheatingServoShutsDown) {
  Rig rig;
  rig.bus.WriteU8(1, tbl::kTorqueEnable.address, 1);
  rig.emulator.SetTemperature(1, 85);
  EXPECT_EQ(rig.bus.ReadU8(1, tbl::kPresentTemperature.address), 85);
  EXPECT_EQ(dxl::HardwareErrorNames(rig.bus.ReadU8(1, tbl::kHardwareErrorStatus.address)),
            "overheating");
  EXPECT_TRUE(rig.bus.alert(1));
  EXPECT_EQ(rig.bus.ReadU8(1, tbl::kTorqueEnable.address), 0);
}

TEST(DynamixelBusTest, ServoMovesTowardItsGoalAtTheProfileVelocity) {
  Rig rig(Servos({1000, 2048, 2048, 2048}));
  constexpr uint32_t kProfileVelocity = 100;                             // units of 0.229 rev/min
  const double ticks_per_second = kProfileVelocity * 0.229 * 4096 / 60;  // 1563 ticks/s
  constexpr int32_t kGoal = 1600;
  rig.bus.WriteU8(1, tbl::kTorqueEnable.address, 1);
  rig.bus.WriteU32(1, tbl::kProfileVelocity.address, kProfileVelocity);  // acceleration 0: a step
  const Clock::time_point start = Clock::now();
  rig.bus.WriteS32(1, tbl::kGoalPosition.address, kGoal);
  // Samples: (time, position), timed at the middle of the read.
  const auto sample = [&] {
    const Clock::time_point before = Clock::now();
    const int32_t position = rig.bus.ReadS32(1, tbl::kPresentPosition.address);
    const Clock::time_point after = Clock::now();
    return std::pair{std::chrono::duration<double>((before - start) + (after - before) / 2).count(),
                     position};
  };
  std::this_thread::sleep_for(milliseconds(60));
  const auto [t1, p1] = sample();
  EXPECT_EQ(rig.bus.ReadU8(1, tbl::kMoving.address), 1);
  EXPECT_EQ(rig.bus.ReadS32(1, tbl::kPresentVelocity.address),
            static_cast<int32_t>(kProfileVelocity));
  std::this_thread::sleep_for(milliseconds(120));
  const auto [t2, p2] = sample();
  ASSERT_LT(p2, kGoal) << "the move (0.38 s) ended before the second sample at " << t2 << " s";
  EXPECT_GT(p1, 1000);
  // Read timing jitter over the 120 ms between samples (a few ms on a loaded machine).
  constexpr double kVelocityRelTolerance = 0.1;
  const double measured = (p2 - p1) / (t2 - t1);
  EXPECT_NEAR(measured, ticks_per_second, kVelocityRelTolerance * ticks_per_second);
  // Position against time since the command, with the same jitter.
  EXPECT_NEAR(p2, 1000 + ticks_per_second * t2, kVelocityRelTolerance * ticks_per_second * t2);
  // It arrives and stops exactly on the goal.
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(2);
  while (rig.bus.ReadU8(1, tbl::kMoving.address) == 1 && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(20));
  }
  EXPECT_EQ(rig.bus.ReadS32(1, tbl::kPresentPosition.address), kGoal);
  EXPECT_EQ(rig.bus.ReadS32(1, tbl::kPresentVelocity.address), 0);
  // The others did not move.
  EXPECT_EQ(rig.bus.ReadS32(2, tbl::kPresentPosition.address), 2048);
}

TEST(DynamixelBusTest, ProfileAccelerationRampsTheVelocity) {
  Rig rig(Servos({1000, 2048, 2048, 2048}));
  // 100 velocity units (1563 ticks/s) reached at 20 acceleration units (4883 ticks/s^2)
  // after 0.32 s.
  rig.bus.WriteU8(1, tbl::kTorqueEnable.address, 1);
  rig.bus.WriteU32(1, tbl::kProfileVelocity.address, 100);
  rig.bus.WriteU32(1, tbl::kProfileAcceleration.address, 20);
  rig.bus.WriteS32(1, tbl::kGoalPosition.address, 3000);
  std::this_thread::sleep_for(milliseconds(80));
  const int32_t early = rig.bus.ReadS32(1, tbl::kPresentVelocity.address);
  std::this_thread::sleep_for(milliseconds(120));
  const int32_t later = rig.bus.ReadS32(1, tbl::kPresentVelocity.address);
  EXPECT_GT(early, 0);
  EXPECT_LT(early, later);
  EXPECT_LT(later, 100);
}

// Plays one servo on a pseudo-terminal: answers the k-th instruction with answers[k].
class ScriptedServo {
 public:
  explicit ScriptedServo(std::vector<std::vector<dxl::Packet>> answers)
      : answers_(std::move(answers)), thread_([this] { Run(); }) {}
  ~ScriptedServo() {
    stop_ = true;
    thread_.join();
  }
  const std::string& path() const { return pty_.slave_path(); }
  int instructions() const { return instructions_; }

 private:
  void Run() {
    dxl::PacketParser parser;
    while (!stop_) {
      pollfd pfd{pty_.master_fd(), POLLIN, 0};
      if (poll(&pfd, 1, 5) <= 0) continue;
      uint8_t buffer[256];
      const ssize_t n = read(pty_.master_fd(), buffer, sizeof(buffer));
      if (n <= 0) continue;
      parser.Feed(buffer, static_cast<size_t>(n));
      while (auto packet = parser.Next()) {
        const size_t k = static_cast<size_t>(instructions_++);
        if (k >= answers_.size()) continue;
        for (const dxl::Packet& answer : answers_[k]) {
          const Bytes bytes = dxl::EncodePacket(answer);
          ASSERT_EQ(write(pty_.master_fd(), bytes.data(), bytes.size()),
                    static_cast<ssize_t>(bytes.size()));
        }
      }
    }
  }

  PseudoTerminal pty_;
  std::vector<std::vector<dxl::Packet>> answers_;
  std::atomic<bool> stop_{false};
  std::atomic<int> instructions_{0};
  std::thread thread_;
};

dxl::Packet PingStatus(uint8_t id, uint8_t error = 0) {
  return {id, dxl::instruction::kStatus, error, {0xFC, 0x03, 46}};
}

TEST(DynamixelBusTest, AnswersFromAnotherServoAreAProtocolError) {
  ScriptedServo servo({{PingStatus(5)}, {PingStatus(5)}, {PingStatus(5)}});
  DynamixelBus bus(servo.path(), kBaud, {kShortTimeout, 2});
  const BusError e = CatchBusError([&] { bus.Ping(3); });
  EXPECT_EQ(e.kind(), BusError::Kind::kProtocol);
  EXPECT_EQ(e.id(), 3);
  EXPECT_TRUE(Contains(e.what(),
                       ": servo 3: no matching status packet (3 tries), got a status "
                       "packet from servo 5"))
      << e.what();
  EXPECT_EQ(bus.stats().unexpected_packets, 3);
}

TEST(DynamixelBusTest, LateAnswerFromAnotherServoIsSkipped) {
  ScriptedServo servo({{PingStatus(5), PingStatus(3)}});
  DynamixelBus bus(servo.path(), kBaud, {kPatientTimeout, 0});
  EXPECT_EQ(bus.Ping(3), 1020);
  EXPECT_EQ(bus.stats().unexpected_packets, 1);
  EXPECT_EQ(bus.stats().retries, 0);
}

TEST(DynamixelBusTest, ServoReportingACorruptedInstructionGetsItAgain) {
  ScriptedServo servo({{PingStatus(3, err::kCrcError)}, {PingStatus(3)}});
  DynamixelBus bus(servo.path(), kBaud, {kPatientTimeout, 2});
  EXPECT_EQ(bus.Ping(3), 1020);
  EXPECT_EQ(bus.stats().retries, 1);
  EXPECT_EQ(bus.stats().crc_errors, 1);
  EXPECT_EQ(servo.instructions(), 2);
}

TEST(DynamixelBusTest, CorruptedAnswersEveryTimeAreACrcError) {
  Rig rig(Servos(), {kPatientTimeout, 2});
  rig.emulator.SetCorruptRate(1.0);
  const auto start = Clock::now();
  const BusError e = CatchBusError([&] { rig.bus.Ping(4); });
  EXPECT_EQ(e.kind(), BusError::Kind::kCrc);
  EXPECT_TRUE(Contains(e.what(), ": servo 4: the status packet failed its CRC check (3 tries"))
      << e.what();
  EXPECT_EQ(rig.bus.stats().crc_errors, 3);
  // A corrupted answer ends the try at once: no waiting for the 100 ms timeouts.
  EXPECT_LT(Clock::now() - start, milliseconds(250));
}

TEST(DynamixelBusTest, OpeningErrorsNameThePort) {
  try {
    DynamixelBus bus("/dev/ttyUSB-saccade-missing", kBaud);
    FAIL() << "expected HardwareError";
  } catch (const HardwareError& e) {
    EXPECT_TRUE(Contains(e.what(), "/dev/ttyUSB-saccade-missing: cannot open")) << e.what();
  }
  PseudoTerminal pty;
  EXPECT_THROW(DynamixelBus(pty.slave_path(), 12345), HardwareError);
  try {
    DynamixelBus bus(pty.slave_path(), kBaud, {milliseconds(0), 2});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_TRUE(Contains(e.what(), "timeout = 0 us")) << e.what();
  }
}

TEST(DynamixelBusTest, StoppedEmulatorIsAPortFailureNotATimeout) {
  Rig rig;
  EXPECT_EQ(rig.bus.Ping(1), 1020);
  rig.emulator.Stop();  // the terminal closes: like an unplugged adapter
  try {
    rig.bus.Ping(1);
    FAIL() << "expected HardwareError";
  } catch (const BusError& e) {
    FAIL() << "a port failure is not a bus error: " << e.what();
  } catch (const HardwareError& e) {
    EXPECT_TRUE(Contains(e.what(), rig.path + ": ")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "unplugged")) << e.what();
  }
}

TEST(DynamixelBusTest, RejectsBadRequestsBeforeSendingThem) {
  PseudoTerminal pty;
  DynamixelBus bus(pty.slave_path(), kBaud);
  EXPECT_THROW(bus.Read(dxl::kBroadcastId, 0, 2), InvalidArgument);
  EXPECT_THROW(bus.Read(1, 0, 0), InvalidArgument);
  try {
    bus.SyncWrite(tbl::kGoalPosition.address, 4, {{1, {0, 0, 0, 0}}, {2, {0, 0}}});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_TRUE(Contains(e.what(), "servo 2: 2 bytes, expected 4")) << e.what();
  }
  EXPECT_THROW(bus.SyncRead(tbl::kPresentPosition.address, 4, {1, 1}), InvalidArgument);
  EXPECT_THROW(bus.WriteItem(1, tbl::kLed, 256), InvalidArgument);
  EXPECT_EQ(bus.stats().instructions, 0);
}

}  // namespace
}  // namespace saccade::hw
