// The Dynamixel head driver (dynamixel_head.h) against the emulated servo bus on a
// pseudo-terminal (servo_emulator.h): the joint-to-servo mapping of robots/popeye.yaml, the
// safety rules of head_driver.h on a real protocol, and each emulated fault.
#include "saccade/hw/dynamixel_head.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <thread>

#include "hw/driver_test_util.h"
#include "saccade/hw/dynamixel_protocol.h"
#include "saccade/hw/hw_error.h"
#include "servo_emulator/servo_emulator.h"

namespace saccade::hw {
namespace {

using testing::kDeg;
using testing::kPopeye;
using testing::ReadUntil;
using testing::Sleep;
constexpr double kTick = 360.0 / 4096.0;  // deg

head::JointState Joints(double pan_deg, double tilt_deg, double left_deg, double right_deg) {
  return head::JointState::Popeye(pan_deg * kDeg, tilt_deg * kDeg, left_deg * kDeg,
                                  right_deg * kDeg);
}

class DynamixelHeadTest : public ::testing::Test {
 protected:
  void Open(SafetyOptions safety = {.watchdog_s = 0}, int retries = 2) {
    emulator_ = std::make_unique<ServoEmulator>();
    port_ = emulator_->Start();
    DynamixelOptions options;
    options.timeout_ms = 10;
    options.retries = retries;
    driver_ = OpenDynamixelHead(head_, port_, options, safety);
  }
  // Goals go out in a Sync Write, which no servo answers: a read's round trip makes sure the
  // emulator has handled it before the test looks.
  void Sync() { driver_->Read(); }
  void TearDown() override {
    driver_.reset();
    if (emulator_) emulator_->Stop();
  }
  const head::HeadModel head_ = head::HeadModel::FromFile(kPopeye);
  std::unique_ptr<ServoEmulator> emulator_;
  std::string port_;
  std::unique_ptr<HeadDriver> driver_;
};

TEST(DynamixelTicksTest, JointAnglesMapThroughZeroOffsetDirectionAndGearRatio) {
  head::ServoMapping servo{
      .id = 1, .zero_offset = std::numbers::pi, .direction = 1, .gear_ratio = 1.0};
  EXPECT_EQ(JointToTicks(servo, 0.0), 2048);
  EXPECT_EQ(JointToTicks(servo, 90 * kDeg), 3072);
  servo.direction = -1;
  EXPECT_EQ(JointToTicks(servo, 90 * kDeg), 1024);
  servo.gear_ratio = 2.0;  // the servo turns twice as far as the joint
  EXPECT_EQ(JointToTicks(servo, 45 * kDeg), 1024);
  EXPECT_NEAR(TicksToJoint(servo, 1024), 45 * kDeg, 1e-12);
  EXPECT_NEAR(TicksToJoint(servo, JointToTicks(servo, 0.3)), 0.3, std::numbers::pi / 4096);
}

TEST_F(DynamixelHeadTest, OpeningProgramsTheServosFromTheHeadDescription) {
  Open();
  for (const ServoSnapshot& s : emulator_->Snapshots()) {
    EXPECT_TRUE(s.torque) << "servo " << int(s.id);
    EXPECT_EQ(s.goal, s.position) << "holds where it is";
  }
  // The servos' own limits and profiles, read back over the bus by another client would
  // need the port; the emulator's last accepted goal and the motion below show them.
  const HeadStatus status = driver_->Read();
  EXPECT_TRUE(status.ready());
  EXPECT_EQ(driver_->name(), "dynamixel on " + port_);
  for (int joint = 0; joint < 4; ++joint) EXPECT_NEAR(status.positions[joint], 0.0, 1e-12);
}

TEST_F(DynamixelHeadTest, CommandsBecomeGoalTicksWithTheMapping) {
  Open();
  driver_->Command(Joints(30, 10, -5, 5));
  Sync();
  // pan: 2048 + 30 deg; tilt turns the other way (direction -1); eyes +-5 deg.
  EXPECT_EQ(emulator_->last_accepted_goal(1), 2048 + std::lround(30 / kTick));
  EXPECT_EQ(emulator_->last_accepted_goal(2), 2048 - std::lround(10 / kTick));
  EXPECT_EQ(emulator_->last_accepted_goal(3), 2048 - std::lround(5 / kTick));
  EXPECT_EQ(emulator_->last_accepted_goal(4), 2048 + std::lround(5 / kTick));
  const HeadStatus arrived = ReadUntil(driver_.operator*(), [](const HeadStatus& s) {
    return !s.moving && std::abs(s.positions[0] - 30 * kDeg) < 0.1 * kDeg;
  });
  EXPECT_NEAR(arrived.positions[0], 30 * kDeg, kTick * kDeg);
  EXPECT_NEAR(arrived.positions[1], 10 * kDeg, kTick * kDeg);
  EXPECT_NEAR(arrived.positions[2], -5 * kDeg, kTick * kDeg);
}

TEST_F(DynamixelHeadTest, LimitsAreNeverSentAndTheMotionIsNeverFasterThanTheDescription) {
  Open();
  const CommandReport report = driver_->Command(Joints(-150, 0, 0, 0));
  EXPECT_TRUE(report.position_clamped[0]);
  Sync();
  EXPECT_EQ(emulator_->last_accepted_goal(1), 2048 - 1024);  // -90 deg, the limit
  double fastest = 0.0;
  double lowest = 0.0;
  const HeadStatus end = ReadUntil(driver_.operator*(), [&](const HeadStatus& s) {
    fastest = std::max(fastest, std::abs(s.velocities[0]));
    lowest = std::min(lowest, s.positions[0]);
    return !s.moving && s.positions[0] < -89.9 * kDeg;
  });
  EXPECT_NEAR(end.positions[0], -90 * kDeg, kTick * kDeg);
  EXPECT_GE(lowest, -90 * kDeg - 1e-9);
  // The profile velocity is the joint's 300 deg/s, rounded down to the servo's unit.
  EXPECT_GT(fastest, 250 * kDeg);
  EXPECT_LE(fastest, 300 * kDeg);
  // The servos themselves refuse goals beyond the joint limits (a second line of defence):
  // the emulator counted no goal outside them.
  for (const ServoSnapshot& s : emulator_->Snapshots()) {
    EXPECT_GE(s.position, 1024 - 1) << int(s.id);
    EXPECT_LE(s.position, 3072 + 1) << int(s.id);
  }
}

TEST_F(DynamixelHeadTest, NonFiniteCommandsSendNothing) {
  Open();
  driver_->Command(Joints(10, 0, 0, 0));
  Sync();
  const int64_t received = emulator_->counters().instructions_received;
  head::JointState bad = Joints(20, 0, 0, 0);
  bad[2] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(driver_->Command(bad), CommandRejected);
  EXPECT_EQ(emulator_->counters().instructions_received, received);
  EXPECT_EQ(emulator_->last_accepted_goal(1), 2048 + std::lround(10 / kTick));
}

TEST_F(DynamixelHeadTest, WatchdogHoldsTheServosWhenCommandsStop) {
  Open({.watchdog_s = 0.05});
  driver_->Command(Joints(90, 0, 0, 0));  // 0.4 s of motion
  // Held: the goal is where the servo stops braking, short of 90 deg, and it settles there.
  const HeadStatus held = ReadUntil(driver_.operator*(), [](const HeadStatus& s) {
    return s.holding && !s.moving && std::abs(s.positions[0] - s.targets[0]) < 2 * kTick * kDeg;
  });
  ASSERT_TRUE(held.holding);
  EXPECT_EQ(held.watchdog_trips, 1);
  EXPECT_NEAR(held.positions[0], held.targets[0], 2 * kTick * kDeg);
  const ServoSnapshot pan = emulator_->Snapshot(1);
  EXPECT_LT(pan.goal, 2048 + 1024 - 50) << "the goal was pulled back from 90 deg";
  EXPECT_NEAR(pan.position, pan.goal, 2);
  EXPECT_LT(held.positions[0], 85 * kDeg);
}

TEST_F(DynamixelHeadTest, OverloadIsReportedAndTheHeadIsSafeUntilCleared) {
  Open();
  driver_->Command(Joints(20, 0, 0, 0));
  emulator_->InjectHardwareError(2, dxl::hardware_error::kOverload);
  const HeadStatus faulty =
      ReadUntil(driver_.operator*(), [](const HeadStatus& s) { return !s.fault.empty(); });
  EXPECT_NE(faulty.fault.find("servo 2 (tilt): overload"), std::string::npos) << faulty.fault;
  EXPECT_FALSE(faulty.ready());
  EXPECT_FALSE(emulator_->Snapshot(2).torque);  // the servo's own shutdown
  try {
    driver_->Command(Joints(-20, 0, 0, 0));
    FAIL() << "a command was accepted by a faulty head";
  } catch (const CommandRejected& error) {
    EXPECT_NE(std::string(error.what()).find("overload"), std::string::npos) << error.what();
  }
  // The others hold where they were.
  const ServoSnapshot pan = emulator_->Snapshot(1);
  EXPECT_TRUE(pan.torque);
  EXPECT_EQ(pan.goal, emulator_->last_accepted_goal(1));
  // Clearing reboots the servo and powers it again.
  driver_->ClearFault();
  const HeadStatus cleared = driver_->Read();
  EXPECT_TRUE(cleared.ready()) << cleared.fault;
  EXPECT_TRUE(emulator_->Snapshot(2).torque);
  EXPECT_EQ(emulator_->Snapshot(2).hardware_error, 0);
  EXPECT_NO_THROW(driver_->Command(Joints(0, 5, 0, 0)));
}

TEST_F(DynamixelHeadTest, OverheatingIsNamed) {
  Open();
  emulator_->SetTemperature(4, 95);
  const HeadStatus faulty =
      ReadUntil(driver_.operator*(), [](const HeadStatus& s) { return !s.fault.empty(); });
  EXPECT_NE(faulty.fault.find("servo 4 (right): overheating"), std::string::npos) << faulty.fault;
  // Still hot: clearing fails and the fault stays.
  EXPECT_THROW(driver_->ClearFault(), Error);
  EXPECT_FALSE(driver_->Read().ready());
  emulator_->SetTemperature(4, 40);
  EXPECT_NO_THROW(driver_->ClearFault());
  EXPECT_TRUE(driver_->Read().ready());
}

TEST_F(DynamixelHeadTest, AServoThatStopsAnsweringIsAFault) {
  Open();
  emulator_->SetSilent(3, true);
  const HeadStatus faulty =
      ReadUntil(driver_.operator*(), [](const HeadStatus& s) { return !s.fault.empty(); });
  EXPECT_NE(faulty.fault.find("servo 3"), std::string::npos) << faulty.fault;
  EXPECT_NE(faulty.fault.find("no status packet"), std::string::npos) << faulty.fault;
  EXPECT_THROW(driver_->Command(Joints(10, 0, 0, 0)), CommandRejected);
  emulator_->SetSilent(3, false);
  driver_->ClearFault();
  EXPECT_TRUE(driver_->Read().ready());
  EXPECT_NO_THROW(driver_->Command(Joints(10, 0, 0, 0)));
}

TEST_F(DynamixelHeadTest, LostAndCorruptedPacketsAreRetriedWithoutAFault) {
  // 5 % of the instructions lost and 5 % of the answers corrupted: with 4 retries a
  // transaction fails with a probability of about 1e-5.
  Open({.watchdog_s = 0}, /*retries=*/4);
  emulator_->SetDropRate(0.05);
  emulator_->SetCorruptRate(0.05);
  for (int i = 0; i < 30; ++i) {
    driver_->Command(Joints(i, 0, 0, 0));
    EXPECT_TRUE(driver_->Read().fault.empty());
  }
  const EmulatorCounters counters = emulator_->counters();
  EXPECT_GT(counters.dropped, 0);
  EXPECT_GT(counters.corrupted, 0);
  EXPECT_TRUE(driver_->Read().ready());
}

TEST_F(DynamixelHeadTest, EveryStatusCorruptedIsAChecksumFault) {
  Open();
  emulator_->SetCorruptRate(1.0);
  const HeadStatus status = driver_->Read();
  EXPECT_NE(status.fault.find("CRC"), std::string::npos) << status.fault;
  EXPECT_FALSE(status.ready());
  EXPECT_THROW(driver_->Command(Joints(5, 0, 0, 0)), CommandRejected);
  emulator_->SetCorruptRate(0.0);
  driver_->ClearFault();
  EXPECT_TRUE(driver_->Read().ready());
}

TEST_F(DynamixelHeadTest, EveryPacketLostIsAFaultNamingThePort) {
  Open();
  emulator_->SetDropRate(1.0);
  const HeadStatus status = driver_->Read();
  EXPECT_NE(status.fault.find(port_), std::string::npos) << status.fault;
  EXPECT_FALSE(status.ready());
}

TEST_F(DynamixelHeadTest, EmergencyStopHoldsTheServos) {
  Open();
  driver_->Command(Joints(-90, 0, 0, 0));
  Sleep(0.05);
  driver_->EmergencyStop();
  const HeadStatus stopped =
      ReadUntil(driver_.operator*(), [](const HeadStatus& s) { return !s.moving; });
  EXPECT_TRUE(stopped.emergency_stopped);
  EXPECT_GT(stopped.positions[0], -85 * kDeg);
  EXPECT_THROW(driver_->Command(Joints(0, 0, 0, 0)), CommandRejected);
  driver_->ClearFault();
  EXPECT_NO_THROW(driver_->Command(Joints(0, 0, 0, 0)));
}

TEST(DynamixelHeadOpenTest, AMissingServoIsNamed) {
  ServoEmulatorOptions emulated;
  emulated.ids = {1, 2, 3};  // no right eye
  ServoEmulator emulator(emulated);
  const std::string port = emulator.Start();
  DynamixelOptions options;
  options.timeout_ms = 5;
  try {
    OpenDynamixelHead(head::HeadModel::FromFile(kPopeye), port, options);
    FAIL() << "opened a head without its right-eye servo";
  } catch (const HardwareError& error) {
    EXPECT_NE(std::string(error.what()).find("servo 4 (right) does not answer a ping"),
              std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find(port), std::string::npos) << error.what();
  }
  try {
    OpenDynamixelHead(head::HeadModel::FromFile(kPopeye), "/dev/no-such-port");
    FAIL() << "opened a missing port";
  } catch (const HardwareError& error) {
    EXPECT_NE(std::string(error.what()).find("/dev/no-such-port"), std::string::npos);
  }
}

}  // namespace
}  // namespace saccade::hw
