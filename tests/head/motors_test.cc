#include "saccade/head/motors.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::head {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Durations are sums of a few divisions and a square root: a few ulps.
constexpr double kDurationRelTolerance = 1e-9;
// Closed-form states evaluated at the same time by different step sizes differ only by the
// rounding of the accumulated time (1000 additions of 1e-3: ~1e-13 s).
constexpr double kDtIndependenceTolerance = 1e-9;
// Tracking evaluates the target's own formula: rounding only.
constexpr double kTrackingTolerance = 1e-9;
// Rounding slack on limits and overshoot (positions of order 1 rad).
constexpr double kRoundingSlack = 1e-12;
// Finite differences of a piecewise-quadratic trajectory over 1 ms: the mean velocity and
// acceleration over a step never exceed the pointwise bounds (plus rounding of x / dt).
constexpr double kFiniteDifferenceSlack = 1e-7;

const std::string kPopeyePath = SACCADE_SOURCE_DIR "/robots/popeye.yaml";

HeadModel Popeye() { return HeadModel::FromFile(kPopeyePath); }

// The classical time-optimal rest-to-rest duration, written independently of the planner.
double ClassicalDuration(double d, double v, double a) {
  d = std::abs(d);
  if (d <= v * v / a) return 2.0 * std::sqrt(d / a);  // triangle: never reaches v
  return d / v + v / a;                               // trapezoid
}

TEST(MotorsTest, StartsAtRestAtTheGivenPositions) {
  const JointState start = head::JointState::Popeye(0.1, -0.2, 0.3, -0.3);
  const Motors motors(Popeye(), start);
  EXPECT_EQ(motors.positions(), start);
  EXPECT_EQ(motors.velocities(), head::JointState::Popeye(0, 0, 0, 0));
  EXPECT_TRUE(motors.Arrived());
  EXPECT_EQ(motors.TimeToTarget(), 0.0);
}

TEST(MotorsTest, SaccadeOfEachJointTakesTheTimeOptimalDuration) {
  const HeadModel head = Popeye();
  // Short (triangle) and long (trapezoid) moves, both signs, for every joint.
  for (int joint = 0; joint < 4; ++joint) {
    const JointLimits& l = head.joint(joint).limits;
    const double v = l.max_velocity;
    const double a = l.max_acceleration;
    // The eyes' range is too short to cruise from 0: long moves go from one side to the other.
    const double half_range = std::min(l.max, -l.min);
    const double short_move = 0.3 * v * v / a;
    const double long_move = 0.9 * half_range;
    ASSERT_GT(2 * long_move, v * v / a)
        << head::JointState::PopeyeNames()->at(joint) << ": the long move must cruise";
    const std::vector<std::pair<double, double>> moves = {
        {0.0, short_move}, {0.0, -short_move}, {-long_move, long_move}, {long_move, -long_move}};
    for (const auto& [x0, x1] : moves) {
      JointState start = head::JointState::Popeye(0, 0, 0, 0);
      start[joint] = x0;
      Motors motors(head, start);
      JointState target = start;
      target[joint] = x1;
      const double d = x1 - x0;
      EXPECT_FALSE(motors.SetTarget(target).any());
      const double expected = ClassicalDuration(d, v, a);
      EXPECT_NEAR(motors.CommandDuration(joint), expected, kDurationRelTolerance * expected)
          << head::JointState::PopeyeNames()->at(joint) << " d = " << d;
      EXPECT_NEAR(motors.TimeToTarget(), expected, kDurationRelTolerance * expected);
      // Just before the end it is still moving; at the end it is at rest on the target.
      motors.Step(expected * (1 - 1e-6));
      EXPECT_FALSE(motors.Arrived(joint, 1e-12));
      EXPECT_GT(std::abs(motors.velocities()[joint]), 0.0);
      motors.Step(expected * 1e-6);
      EXPECT_NEAR(motors.positions()[joint], x1, kRoundingSlack);
      EXPECT_NEAR(motors.velocities()[joint], 0.0, 1e-9);
      motors.Step(1.0);
      EXPECT_EQ(motors.positions()[joint], x1);
      EXPECT_EQ(motors.velocities()[joint], 0.0);
      EXPECT_TRUE(motors.Arrived());
      EXPECT_EQ(motors.TimeToTarget(), 0.0);
    }
  }
}

TEST(MotorsTest, SaccadeReachesPeakVelocityOnlyWhenTheMoveIsLong) {
  const HeadModel head = Popeye();
  const JointLimits& l = head.joint(0).limits;
  Motors motors(head);
  motors.SetJointTarget(0, 80 * kDeg);
  const double ramp = l.max_velocity / l.max_acceleration;
  motors.Step(ramp + 1e-3);  // cruising
  EXPECT_NEAR(motors.velocities()[0], l.max_velocity, 1e-9);
  EXPECT_EQ(motors.accelerations()[0], 0.0);
}

// Records a trajectory at a fixed step and checks every bound, pointwise and by finite
// differences. Returns the positions.
std::vector<double> RecordAndCheck(Motors& motors, int joint, double dt, int steps,
                                   const std::string& what) {
  const JointLimits& l = motors.limits(joint);
  std::vector<double> x{motors.positions()[joint]};
  std::vector<double> v{motors.velocities()[joint]};
  for (int k = 0; k < steps; ++k) {
    motors.Step(dt);
    x.push_back(motors.positions()[joint]);
    v.push_back(motors.velocities()[joint]);
    const double a = motors.accelerations()[joint];
    EXPECT_LE(std::abs(v.back()), l.max_velocity * (1 + kRoundingSlack)) << what << " k=" << k;
    EXPECT_LE(std::abs(a), l.max_acceleration) << what << " k=" << k;
    EXPECT_GE(x.back(), l.min) << what << " k=" << k;
    EXPECT_LE(x.back(), l.max) << what << " k=" << k;
    const double fd_v = (x[k + 1] - x[k]) / dt;
    const double fd_a = (v[k + 1] - v[k]) / dt;
    EXPECT_LE(std::abs(fd_v), l.max_velocity * (1 + kFiniteDifferenceSlack)) << what;
    EXPECT_LE(std::abs(fd_a), l.max_acceleration * (1 + kFiniteDifferenceSlack)) << what;
    // The velocity is the derivative of the position: the mean velocity over the step lies
    // within the end velocities, widened by a dt where the acceleration switches sign inside.
    const double slack = l.max_acceleration * dt + 1e-9;
    EXPECT_GE(fd_v, std::min(v[k], v[k + 1]) - slack) << what << " k=" << k;
    EXPECT_LE(fd_v, std::max(v[k], v[k + 1]) + slack) << what << " k=" << k;
    if (::testing::Test::HasFailure()) break;
  }
  return x;
}

TEST(MotorsTest, RandomSaccadesFromRandomVelocitiesStayWithinEveryLimit) {
  const HeadModel head = Popeye();
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int joint = trial % 4;
    const JointLimits& l = head.joint(joint).limits;
    // A random start that can stop within the limits, at a random velocity.
    double x0 = l.min + (l.max - l.min) * unit(rng);
    double v0 = l.max_velocity * (2 * unit(rng) - 1);
    const double stop = x0 + v0 * std::abs(v0) / (2 * l.max_acceleration);
    if (!l.Contains(stop)) v0 = 0.0;
    JointState positions = head::JointState::Popeye(0, 0, 0, 0),
               velocities = head::JointState::Popeye(0, 0, 0, 0);
    positions[joint] = x0;
    velocities[joint] = v0;
    Motors motors(head);
    motors.Reset(positions, velocities);
    // Targets anywhere, some beyond the limits.
    const double target = (l.min - 0.2) + (l.max - l.min + 0.4) * unit(rng);
    const bool clamped = motors.SetJointTarget(joint, target);
    EXPECT_EQ(clamped, !l.Contains(target));
    const double goal = std::clamp(target, l.min, l.max);
    const double duration = motors.CommandDuration(joint);
    const double dt = 1e-3;
    RecordAndCheck(motors, joint, dt, static_cast<int>(duration / dt) + 10,
                   "trial " + std::to_string(trial));
    EXPECT_EQ(motors.positions()[joint], goal) << "trial " << trial;
    EXPECT_EQ(motors.velocities()[joint], 0.0) << "trial " << trial;
    if (HasFailure()) break;
  }
}

TEST(MotorsTest, SaccadeFromRestNeverOvershootsItsTarget) {
  const HeadModel head = Popeye();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const int joint = trial % 4;
    const JointLimits& l = head.joint(joint).limits;
    const double x0 = l.min + (l.max - l.min) * unit(rng);
    const double target = l.min + (l.max - l.min) * unit(rng);
    JointState start = head::JointState::Popeye(0, 0, 0, 0);
    start[joint] = x0;
    Motors motors(head, start);
    motors.SetJointTarget(joint, target);
    const double sign = target > x0 ? 1.0 : -1.0;
    double previous = x0;
    for (int k = 0; k < 2000; ++k) {
      motors.Step(5e-4);
      const double x = motors.positions()[joint];
      EXPECT_LE(sign * (x - target), kRoundingSlack) << "trial " << trial;
      EXPECT_GE(sign * (x - previous), 0.0) << "trial " << trial << ": monotone";
      previous = x;
    }
    if (HasFailure()) break;
  }
}

TEST(MotorsTest, ReversingMidFlightStaysWithinLimitsAndEndsOnTheNewTarget) {
  const HeadModel head = Popeye();
  for (int joint = 0; joint < 4; ++joint) {
    const JointLimits& l = head.joint(joint).limits;
    JointState start = head::JointState::Popeye(0, 0, 0, 0);
    start[joint] = 0.8 * l.min;
    Motors motors(head, start);
    motors.SetJointTarget(joint, 0.8 * l.max);
    // Until it is at full speed towards max.
    motors.Step(l.max_velocity / l.max_acceleration);
    ASSERT_NEAR(motors.velocities()[joint], l.max_velocity, 1e-9);
    const double x_switch = motors.positions()[joint];
    EXPECT_FALSE(motors.SetJointTarget(joint, 0.8 * l.min));
    const double stop = x_switch + l.max_velocity * l.max_velocity / (2 * l.max_acceleration);
    // It brakes at once, at the acceleration limit.
    EXPECT_EQ(motors.accelerations()[joint], -l.max_acceleration);
    const std::vector<double> x = RecordAndCheck(
        motors, joint, 1e-3, static_cast<int>(motors.CommandDuration(joint) / 1e-3) + 10,
        head::JointState::PopeyeNames()->at(joint));
    EXPECT_NEAR(*std::max_element(x.begin(), x.end()), stop, 1e-6) << "overshoot = braking";
    EXPECT_EQ(motors.positions()[joint], 0.8 * l.min);
    EXPECT_EQ(motors.velocities()[joint], 0.0);
    // The duration is braking, then a rest-to-rest saccade from where it stopped.
    const double expected =
        l.max_velocity / l.max_acceleration +
        ClassicalDuration(stop - 0.8 * l.min, l.max_velocity, l.max_acceleration);
    EXPECT_NEAR(motors.CommandDuration(joint), expected, kDurationRelTolerance * expected);
  }
}

TEST(MotorsTest, StateDoesNotDependOnTheStepSize) {
  const HeadModel head = Popeye();
  const JointState start = head::JointState::Popeye(0.1, 0.2, -0.1, 0.05);
  const JointState target = head::JointState::Popeye(-1.2, 0.5, 0.4, -0.6);
  const JointState velocity = head::JointState::Popeye(0.3, -0.2, 0.0, 1.0);
  for (bool pursuit : {false, true}) {
    for (double t_end : {0.05, 0.123, 0.4, 1.0, 3.0}) {
      Motors fine(head, start), coarse(head, start), once(head, start);
      for (Motors* m : {&fine, &coarse, &once}) {
        pursuit ? m->SetTarget(target, velocity) : m->SetTarget(target);
      }
      const int n = static_cast<int>(std::lround(t_end / 1e-3));
      for (int k = 0; k < n; ++k) fine.Step(1e-3);
      const int m10 = static_cast<int>(std::lround(t_end / 1e-2));
      for (int k = 0; k < m10; ++k) coarse.Step(1e-2);
      coarse.Step(std::max(0.0, t_end - coarse.time()));
      once.Step(t_end);
      for (int joint = 0; joint < 4; ++joint) {
        EXPECT_NEAR(fine.positions()[joint], once.positions()[joint], kDtIndependenceTolerance)
            << head::JointState::PopeyeNames()->at(joint) << " t=" << t_end
            << " pursuit=" << pursuit;
        EXPECT_NEAR(coarse.positions()[joint], once.positions()[joint], kDtIndependenceTolerance);
        EXPECT_NEAR(fine.velocities()[joint], once.velocities()[joint], kDtIndependenceTolerance);
        EXPECT_NEAR(coarse.velocities()[joint], once.velocities()[joint], kDtIndependenceTolerance);
      }
    }
  }
}

TEST(MotorsTest, RepeatingTheSameCommandEveryStepDoesNotChangeTheMotion) {
  // A closed loop re-sends its target every frame: re-planning from the current state must
  // continue the same time-optimal motion, for saccades and for pursuits.
  const HeadModel head = Popeye();
  const JointState start = head::JointState::Popeye(0.3, -0.2, 0.2, -0.1);
  const JointState target = head::JointState::Popeye(-1.0, 0.4, -0.3, 0.5);
  const JointState velocity = head::JointState::Popeye(0.4, -0.3, 0.5, 0.2);
  for (bool pursuit : {false, true}) {
    Motors once(head, start), every_frame(head, start);
    pursuit ? once.SetTarget(target, velocity) : once.SetTarget(target);
    for (int k = 0; k < 150; ++k) {  // 1.5 s at 100 Hz
      JointState now = target;
      for (int joint = 0; joint < 4; ++joint) {
        now[joint] += pursuit ? velocity[joint] * every_frame.time() : 0.0;
      }
      pursuit ? every_frame.SetTarget(now, velocity) : every_frame.SetTarget(now);
      every_frame.Step(0.01);
      once.Step(0.01);
      for (int joint = 0; joint < 4; ++joint) {
        ASSERT_NEAR(every_frame.positions()[joint], once.positions()[joint],
                    kDtIndependenceTolerance)
            << head::JointState::PopeyeNames()->at(joint) << " k=" << k << " pursuit=" << pursuit;
        ASSERT_NEAR(every_frame.velocities()[joint], once.velocities()[joint],
                    kDtIndependenceTolerance)
            << head::JointState::PopeyeNames()->at(joint) << " k=" << k << " pursuit=" << pursuit;
      }
    }
  }
}

TEST(MotorsTest, PursuitConvergesThenTracksWithZeroLag) {
  const HeadModel head = Popeye();
  for (int joint = 0; joint < 4; ++joint) {
    const JointLimits& l = head.joint(joint).limits;
    for (double sign : {1.0, -1.0}) {
      // A target ahead and moving at a quarter of the velocity limit, from a joint moving the
      // other way: it must turn, catch up and lock on.
      const double vt = sign * 0.25 * l.max_velocity;
      const double p0 = -sign * 0.4 * std::min(l.max, -l.min);
      JointState start = head::JointState::Popeye(0, 0, 0, 0),
                 start_v = head::JointState::Popeye(0, 0, 0, 0);
      start[joint] = -sign * 0.5 * std::min(l.max, -l.min);
      start_v[joint] = -0.5 * vt;
      Motors motors(head);
      motors.Reset(start, start_v);
      EXPECT_FALSE(motors.SetJointTarget(joint, p0, vt));
      const double meet = motors.CommandDuration(joint);
      ASSERT_GT(meet, 0.0);
      // The target reaches the braking point later than the joint meets it.
      const double limit = sign > 0 ? l.max : l.min;
      const double t_brake = (limit - sign * vt * vt / (2 * l.max_acceleration) - p0) / vt;
      ASSERT_LT(meet, t_brake) << head::JointState::PopeyeNames()->at(joint);
      RecordAndCheck(motors, joint, 1e-3, static_cast<int>(meet / 1e-3) + 1,
                     head::JointState::PopeyeNames()->at(joint));
      // From the meeting time until the braking point: exact tracking.
      double t = motors.command_time(joint);
      while (t < t_brake - 1e-3) {
        EXPECT_NEAR(motors.positions()[joint], p0 + vt * t, kTrackingTolerance)
            << head::JointState::PopeyeNames()->at(joint) << " t=" << t;
        EXPECT_NEAR(motors.velocities()[joint], vt, kTrackingTolerance);
        EXPECT_TRUE(motors.Arrived(joint));
        // The target the joint is on, and how fast it moves (what a joint state sends).
        EXPECT_NEAR(motors.targets()[joint], p0 + vt * t, kTrackingTolerance);
        EXPECT_EQ(motors.target_velocities()[joint], vt);
        motors.Step(1e-3);
        t = motors.command_time(joint);
      }
      // Then it stops on the limit the target runs into, never past it.
      RecordAndCheck(motors, joint, 1e-3, 1000, head::JointState::PopeyeNames()->at(joint));
      EXPECT_EQ(motors.positions()[joint], limit);
      EXPECT_EQ(motors.velocities()[joint], 0.0);
    }
  }
}

TEST(MotorsTest, PursuitInterceptIsTimeOptimalFromRest) {
  // From rest at 0, a target at p moving away at vt. Checked against an independent
  // criterion: the furthest the joint can get by time T while ending at velocity vt.
  const HeadModel head = Popeye();
  const JointLimits& l = head.joint(2).limits;
  const double p = 0.05;
  const double vt = 0.3 * l.max_velocity;
  Motors motors(head);
  motors.SetJointTarget(2, p, vt);
  const double meet = motors.CommandDuration(2);
  // Feasibility of meeting at T from rest under a bang-bang profile with at most one switch
  // and |v| <= vmax: the furthest position reachable at time T while ending at velocity vt.
  auto reachable = [&](double T) {
    const double a = l.max_acceleration, v = l.max_velocity;
    // accelerate to peak u, then decelerate to vt: t1 = u/a, t3 = (u - vt)/a.
    // Maximise distance over u <= v subject to t1 + t3 <= T (cruise fills the rest).
    const double u = std::min(v, (a * T + vt) / 2);
    const double t1 = u / a, t3 = (u - vt) / a;
    if (t1 + t3 > T + 1e-15) return -1.0;
    return u * u / (2 * a) + u * (T - t1 - t3) + (u * u - vt * vt) / (2 * a);
  };
  EXPECT_GE(reachable(meet) - (p + vt * meet), -1e-9) << "meets no earlier than possible";
  EXPECT_LT(reachable(meet * (1 - 1e-6)) - (p + vt * meet * (1 - 1e-6)), 0.0)
      << "no earlier meeting is possible";
}

TEST(MotorsTest, TargetsBeyondTheLimitsAreClampedAndNeverExceeded) {
  const HeadModel head = Popeye();
  Motors motors(head);
  const JointState far = head::JointState::Popeye(200 * kDeg, -100 * kDeg, 60 * kDeg, -1e6);
  const ClampReport report = motors.SetTarget(far);
  EXPECT_TRUE(report.any());
  for (int joint = 0; joint < 4; ++joint)
    EXPECT_TRUE(report[joint]) << head::JointState::PopeyeNames()->at(joint);
  EXPECT_EQ(motors.clamped_commands(), 4);
  const JointState expected =
      head::JointState::Popeye(head.joint(0).limits.max, head.joint(1).limits.min,
                               head.joint(2).limits.max, head.joint(3).limits.min);
  EXPECT_EQ(motors.targets(), expected);
  for (int joint = 0; joint < 4; ++joint) {
    Motors copy = motors;
    RecordAndCheck(copy, joint, 1e-3, 2000, head::JointState::PopeyeNames()->at(joint));
  }
  motors.Step(10.0);
  EXPECT_EQ(motors.positions(), expected);
  // Too fast a pursuit is clamped to the velocity limit, and reported.
  EXPECT_TRUE(motors.SetJointTarget(0, 0.0, 2 * head.joint(0).limits.max_velocity));
  EXPECT_EQ(motors.clamped_commands(), 5);
  RecordAndCheck(motors, 0, 1e-3, 3000, "fast pursuit");
  EXPECT_FALSE(motors.SetJointTarget(0, 0.1));
  EXPECT_EQ(motors.clamped_commands(), 5);
}

TEST(MotorsTest, NonFiniteTargetsThrowNamingTheJointAndChangeNothing) {
  const HeadModel head = Popeye();
  Motors motors(head);
  motors.SetTarget(head::JointState::Popeye(0.5, 0.2, -0.1, 0.1));
  motors.Step(0.05);
  const JointState x = motors.positions(), v = motors.velocities(), t = motors.targets();
  const double remaining = motors.TimeToTarget();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto expect_throw = [&](auto&& command, const std::string& needle) {
    try {
      command();
      ADD_FAILURE() << "no throw for " << needle;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    EXPECT_EQ(motors.positions(), x);
    EXPECT_EQ(motors.velocities(), v);
    EXPECT_EQ(motors.targets(), t);
    EXPECT_EQ(motors.TimeToTarget(), remaining);
  };
  expect_throw([&] { motors.SetTarget(head::JointState::Popeye(0.0, 0.0, nan, 0.0)); },
               "left target position = nan");
  expect_throw(
      [&] {
        motors.SetTarget(head::JointState::Popeye(0.0, 0.0, 0.0, 0.0),
                         head::JointState::Popeye(0, inf, 0, 0));
      },
      "tilt target velocity = inf");
  expect_throw([&] { motors.SetJointTarget(3, -inf); }, "right target position = -inf");
  expect_throw([&] { motors.Step(nan); }, "Motors::Step: dt = nan");
  expect_throw([&] { motors.Step(-1.0); }, "dt = -1");
  expect_throw([&] { motors.Reset(head::JointState::Popeye(0, 0, 0, 2.0)); }, "right position = 2");
  expect_throw(
      [&] {
        motors.Reset(head::JointState::Popeye(0, 0, 0, 0), head::JointState::Popeye(100, 0, 0, 0));
      },
      "pan velocity = 100");
  // pan at 89 deg moving at 300 deg/s towards 90: needs 15 deg to stop.
  expect_throw(
      [&] {
        motors.Reset(head::JointState::Popeye(89 * kDeg, 0, 0, 0),
                     head::JointState::Popeye(300 * kDeg, 0, 0, 0));
      },
      "cannot stop before its limit");
  EXPECT_EQ(motors.clamped_commands(), 0);
}

TEST(MotorsTest, ResetWithVelocityBrakesToRest) {
  const HeadModel head = Popeye();
  Motors motors(head);
  const JointLimits& l = head.joint(1).limits;
  motors.Reset(head::JointState::Popeye(0, 0.1, 0, 0),
               head::JointState::Popeye(0, -l.max_velocity, 0, 0));
  const double stop = 0.1 - l.max_velocity * l.max_velocity / (2 * l.max_acceleration);
  EXPECT_NEAR(motors.targets()[1], stop, kRoundingSlack);
  EXPECT_NEAR(motors.TimeToTarget(1), l.max_velocity / l.max_acceleration, kRoundingSlack);
  motors.Step(1.0);
  EXPECT_NEAR(motors.positions()[1], stop, kRoundingSlack);
  EXPECT_TRUE(motors.Arrived());
}

}  // namespace
}  // namespace saccade::head
