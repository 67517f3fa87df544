#include "saccade/head/joint_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace saccade::head {
namespace {

// Rounding slack on positions and velocities of order 1 (rad, rad/s).
constexpr double kRoundingSlack = 1e-12;
// Tracking evaluates a straight line anchored on the target's own formula: rounding only.
constexpr double kTrackingTolerance = 1e-9;

// An eye of robots/popeye.yaml: +-45 deg, 600 deg/s, 6000 deg/s^2.
JointLimits Eye() {
  const double deg = std::acos(-1.0) / 180.0;
  return JointLimits{-45 * deg, 45 * deg, 600 * deg, 6000 * deg};
}

// Samples the profile densely and checks every bound pointwise and by finite differences.
void ExpectWithinLimits(const JointProfile& p, const JointLimits& l, double t_end,
                        const std::string& what) {
  const double dt = 2.5e-4;
  double x_prev = p.Position(0.0), v_prev = p.Velocity(0.0);
  for (double t = dt; t <= t_end; t += dt) {
    const double x = p.Position(t), v = p.Velocity(t);
    ASSERT_GE(x, l.min) << what << " t=" << t;
    ASSERT_LE(x, l.max) << what << " t=" << t;
    ASSERT_LE(std::abs(v), l.max_velocity * (1 + kRoundingSlack)) << what << " t=" << t;
    ASSERT_LE(std::abs(p.Acceleration(t)), l.max_acceleration) << what;
    ASSERT_LE(std::abs(x - x_prev) / dt, l.max_velocity * (1 + 1e-7)) << what << " t=" << t;
    ASSERT_LE(std::abs(v - v_prev) / dt, l.max_acceleration * (1 + 1e-7)) << what << " t=" << t;
    x_prev = x;
    v_prev = v;
  }
}

TEST(JointProfileTest, DefaultIsAtRestForever) {
  const JointProfile p(0.25);
  for (double t : {0.0, 1.0, 1e6}) {
    EXPECT_EQ(p.Position(t), 0.25);
    EXPECT_EQ(p.Velocity(t), 0.0);
    EXPECT_EQ(p.Acceleration(t), 0.0);
  }
  EXPECT_EQ(p.duration(), 0.0);
}

TEST(JointProfileTest, RandomPursuitsStayWithinLimitsAndTrackOrStopOnTheLimit) {
  const JointLimits l = Eye();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int tracked = 0, cut = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const std::string what = "trial " + std::to_string(trial);
    const double x0 = l.min + (l.max - l.min) * unit(rng);
    double v0 = l.max_velocity * (2 * unit(rng) - 1);
    if (!l.Contains(x0 + v0 * std::abs(v0) / (2 * l.max_acceleration))) v0 = 0.0;
    const double target = l.min + (l.max - l.min) * unit(rng);
    // Both directions, from 5% to 90% of the velocity limit.
    const double vt = (unit(rng) < 0.5 ? -1 : 1) * l.max_velocity * (0.05 + 0.85 * unit(rng));
    const JointProfile p = JointProfile::Plan(l, x0, v0, target, vt);
    EXPECT_EQ(p.Position(0.0), x0) << what;
    EXPECT_NEAR(p.Velocity(0.0), v0, kRoundingSlack) << what;
    const double limit = vt > 0 ? l.max : l.min;
    const double t_stop = (limit - target) / vt;  // when the target reaches the limit
    ExpectWithinLimits(p, l, std::max(p.duration(), t_stop) + 0.5, what);
    if (!p.cut_at_limit()) {
      ++tracked;
      // Between meeting it and braking for the limit, the joint is on the target.
      const double t_brake = t_stop - std::abs(vt) / (2 * l.max_acceleration);
      for (double t = p.duration(); t < t_brake; t += 1e-3) {
        ASSERT_NEAR(p.Position(t), target + vt * t, kTrackingTolerance) << what << " t=" << t;
        ASSERT_NEAR(p.Velocity(t), vt, kTrackingTolerance) << what;
        ASSERT_EQ(p.TargetPosition(t), target + vt * t);
      }
    } else {
      ++cut;
    }
    // In the end both the target and the joint rest on the limit.
    const double late = std::max(p.duration(), t_stop) + 1.0;
    EXPECT_EQ(p.Position(late), limit) << what;
    EXPECT_EQ(p.Velocity(late), 0.0) << what;
    EXPECT_EQ(p.TargetPosition(late), limit) << what;
    if (HasFailure()) break;
  }
  // Both branches are exercised.
  EXPECT_GT(tracked, 50);
  EXPECT_GT(cut, 10);
}

TEST(JointProfileTest, PursuitThatCannotInterceptInsideTheRangeGoesToTheLimit) {
  const JointLimits l = Eye();
  // Joint near max, rushing towards it; the target just behind it, also heading to max but
  // already past its braking point: the joint stops on max, time-optimally.
  const double v0 = 0.5 * l.max_velocity;
  const double x0 = l.max - 1.01 * v0 * v0 / (2 * l.max_acceleration);
  const JointProfile p = JointProfile::Plan(l, x0, v0, x0 - 0.01, 0.5 * l.max_velocity);
  EXPECT_TRUE(p.cut_at_limit());
  // Straight braking onto the limit (distance slightly more than the stopping distance).
  EXPECT_NEAR(p.duration(), v0 / l.max_acceleration, 1e-3);
  EXPECT_EQ(p.Position(p.duration() + 1e-9), l.max);
  ExpectWithinLimits(p, l, 1.0, "cut");
}

TEST(JointProfileTest, ZeroVelocityPursuitIsASaccade) {
  const JointLimits l = Eye();
  const JointProfile saccade = JointProfile::Plan(l, 0.1, -2.0, -0.3, 0.0);
  EXPECT_FALSE(saccade.cut_at_limit());
  EXPECT_EQ(saccade.TargetPosition(0.0), -0.3);
  EXPECT_EQ(saccade.TargetVelocity(0.0), 0.0);
  EXPECT_EQ(saccade.Position(saccade.duration()), -0.3);
  ExpectWithinLimits(saccade, l, 1.0, "saccade");
}

}  // namespace
}  // namespace saccade::head
