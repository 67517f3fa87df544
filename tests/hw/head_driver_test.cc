// The head driver's safety rules (head_driver.h), on the simulated head: the same base class
// enforces them for every driver (dynamixel_head_test.cc checks them on the servo bus).
#include "saccade/hw/head_driver.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <thread>

#include "hw/driver_test_util.h"

namespace saccade::hw {
namespace {

using testing::kDeg;
using testing::kPopeye;
using testing::ReadUntil;
using testing::Sleep;
head::JointState Pan(double rad) {
  head::JointState s = head::JointState::Popeye(0, 0, 0, 0);
  s[0] = rad;
  return s;
}

TEST(HeadDriverTest, NonFiniteValuesAreRejectedAndNothingIsSent) {
  SimHeadDriver driver(head::HeadModel::FromFile(kPopeye), {.watchdog_s = 0});
  head::JointState bad = head::JointState::Popeye(0, 0, 0, 0);
  bad[1] = std::numeric_limits<double>::quiet_NaN();
  try {
    driver.Command(bad);
    FAIL() << "no CommandRejected";
  } catch (const CommandRejected& error) {
    EXPECT_NE(std::string(error.what()).find("joint tilt position is nan"), std::string::npos)
        << error.what();
  }
  head::JointState fast = head::JointState::Popeye(0, 0, 0, 0);
  fast[3] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(driver.Command({}, fast), CommandRejected);
  const HeadStatus status = driver.Read();
  EXPECT_EQ(status.commands, 0);
  EXPECT_EQ(status.rejected_commands, 2);
  EXPECT_EQ(status.targets, head::JointState::Popeye(0, 0, 0, 0));
  EXPECT_EQ(status.positions, head::JointState::Popeye(0, 0, 0, 0));
}

TEST(HeadDriverTest, TargetsOutsideTheLimitsAreClampedAndReported) {
  const auto head = head::HeadModel::FromFile(kPopeye);
  SimHeadDriver driver(head, {.watchdog_s = 0});
  head::JointState target = head::JointState::Popeye(0, 0, 0, 0);
  target[0] = 120 * kDeg;
  target[2] = -80 * kDeg;
  target[1] = 10 * kDeg;
  const CommandReport report = driver.Command(target);
  EXPECT_TRUE(report.position_clamped[0]);
  EXPECT_FALSE(report.position_clamped[1]);
  EXPECT_TRUE(report.position_clamped[2]);
  EXPECT_DOUBLE_EQ(report.sent_positions[0], head.joint(0).limits.max);
  EXPECT_DOUBLE_EQ(report.sent_positions[2], head.joint(2).limits.min);
  EXPECT_DOUBLE_EQ(report.sent_positions[1], 10 * kDeg);
  EXPECT_NE(report.description.find("pan target 120.00 deg clamped to 90.00 deg"),
            std::string::npos)
      << report.description;
  // The head gets there and never beyond.
  double max_pan = 0.0;
  const HeadStatus status = ReadUntil(driver, [&](const HeadStatus& s) {
    max_pan = std::max(max_pan, s.positions[0]);
    return !s.moving && s.positions[0] > 89 * kDeg;
  });
  EXPECT_NEAR(status.positions[0], 90 * kDeg, 1e-6);
  EXPECT_LE(max_pan, 90 * kDeg + 1e-12);
  EXPECT_EQ(status.limited_commands, 1);
  EXPECT_EQ(status.commands, 1);
}

TEST(HeadDriverTest, PursuitFasterThanTheVelocityLimitIsLimited) {
  const auto head = head::HeadModel::FromFile(kPopeye);
  SimHeadDriver driver(head, {.watchdog_s = 0});
  head::JointState velocity = head::JointState::Popeye(0, 0, 0, 0);
  velocity[0] = -1000 * kDeg;
  const CommandReport report = driver.Command(head.Home(), velocity);
  EXPECT_TRUE(report.velocity_limited[0]);
  EXPECT_DOUBLE_EQ(report.sent_velocities[0], -head.joint(0).limits.max_velocity);
  EXPECT_NE(report.description.find("pan velocity -1000.0 deg/s limited to -300.0 deg/s"),
            std::string::npos)
      << report.description;
  double fastest = 0.0;
  ReadUntil(
      driver,
      [&](const HeadStatus& s) {
        fastest = std::max(fastest, std::abs(s.velocities[0]));
        return s.positions[0] < -89 * kDeg;
      },
      2.0);
  EXPECT_GT(fastest, 250 * kDeg);
  EXPECT_LE(fastest, 300 * kDeg + 1e-9);
}

TEST(HeadDriverTest, WatchdogHoldsThePositionWhenCommandsStop) {
  SimHeadDriver driver(head::HeadModel::FromFile(kPopeye), {.watchdog_s = 0.05});
  // A 90 deg saccade takes about 0.4 s; the watchdog stops it after 0.05 s.
  driver.Command(Pan(90 * kDeg));
  const HeadStatus held = ReadUntil(driver, [](const HeadStatus& s) { return s.holding; });
  ASSERT_TRUE(held.holding);
  EXPECT_EQ(held.watchdog_trips, 1);
  // At rest: slower than the `moving` threshold and settled on the hold's target. `moving`
  // goes false at 0.5 deg/s, a few nanoradians before the profile ends (seen under load: the
  // position 1.3e-9 rad short of the target when `moving` went false), so wait for both.
  const HeadStatus rest = ReadUntil(driver, [](const HeadStatus& s) {
    return !s.moving && std::abs(s.targets[0] - s.positions[0]) <= 1e-9;
  });
  EXPECT_FALSE(rest.moving);
  EXPECT_GT(rest.positions[0], 0.1 * kDeg);
  EXPECT_LT(rest.positions[0], 85 * kDeg) << "the watchdog did not stop the saccade";
  EXPECT_NEAR(rest.targets[0], rest.positions[0], 1e-9);
  Sleep(0.1);
  // Held: settled, it stays within the motors' settling tolerance (1e-9 rad, as above).
  EXPECT_NEAR(driver.Read().positions[0], rest.positions[0], 1e-9);
  EXPECT_EQ(driver.Read().watchdog_trips, 1);  // holding already: it does not fire again
  // The next command moves again.
  driver.Command(Pan(0.0));
  EXPECT_FALSE(driver.Read().holding);
}

TEST(HeadDriverTest, CommandsKeepTheWatchdogQuiet) {
  SimHeadDriver driver(head::HeadModel::FromFile(kPopeye), {.watchdog_s = 0.2});
  for (int i = 0; i < 20; ++i) {
    driver.Command(Pan(i * kDeg));
    Sleep(0.02);
  }
  EXPECT_EQ(driver.Read().watchdog_trips, 0);
}

TEST(HeadDriverTest, EmergencyStopHoldsAndRejectsUntilCleared) {
  SimHeadDriver driver(head::HeadModel::FromFile(kPopeye), {.watchdog_s = 0});
  driver.Command(Pan(-90 * kDeg));
  Sleep(0.05);
  driver.EmergencyStop();
  // Stopped: every joint at rest, not merely slower than HeadStatus::moving's threshold (a
  // joint still braking below it moves on, by up to a few tenths of a milliradian).
  const HeadStatus stopped = ReadUntil(driver, [](const HeadStatus& s) {
    return s.velocities == head::JointState::Popeye(0, 0, 0, 0);
  });
  EXPECT_TRUE(stopped.emergency_stopped);
  EXPECT_FALSE(stopped.ready());
  EXPECT_GT(stopped.positions[0], -85 * kDeg);
  try {
    driver.Command(Pan(0.0));
    FAIL() << "no CommandRejected";
  } catch (const CommandRejected& error) {
    EXPECT_NE(std::string(error.what()).find("emergency stop"), std::string::npos);
  }
  Sleep(0.05);
  EXPECT_NEAR(driver.Read().positions[0], stopped.positions[0], 1e-12);
  driver.ClearFault();
  EXPECT_TRUE(driver.Read().ready());
  driver.Command(Pan(0.0));
  EXPECT_NEAR(
      ReadUntil(driver,
                [](const HeadStatus& s) { return !s.moving && std::abs(s.positions[0]) < 1e-6; })
          .positions[0],
      0.0, 1e-6);
}

TEST(HeadDriverTest, TorqueOffRejectsCommandsAndStopBrakes) {
  SimHeadDriver driver(head::HeadModel::FromFile(kPopeye), {.watchdog_s = 0});
  driver.SetTorque(false);
  EXPECT_FALSE(driver.Read().torque);
  try {
    driver.Command(Pan(0.1));
    FAIL() << "no CommandRejected";
  } catch (const CommandRejected& error) {
    EXPECT_NE(std::string(error.what()).find("torque is off"), std::string::npos);
  }
  driver.SetTorque(true);
  driver.Command(Pan(90 * kDeg));
  Sleep(0.05);
  driver.Stop();
  const HeadStatus status = ReadUntil(driver, [](const HeadStatus& s) { return !s.moving; });
  EXPECT_LT(status.positions[0], 85 * kDeg);
  EXPECT_FALSE(status.emergency_stopped);  // a stop is not latched
  EXPECT_NO_THROW(driver.Command(Pan(0.0)));
}

TEST(HeadDriverTest, BadOptionsAreNamed) {
  try {
    SimHeadDriver driver(head::HeadModel::FromFile(kPopeye), {.watchdog_s = -1});
    FAIL() << "no InvalidArgument";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("watchdog_s"), std::string::npos);
  }
}

}  // namespace
}  // namespace saccade::hw
