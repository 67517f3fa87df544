#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace saccade::scene {
namespace {

using geometry::Pose;

// Interpolation and rotation in double: a few hundred ulps at most.
constexpr double kTolerance = 1e-12;
constexpr double kPi = std::numbers::pi;

Pose MakePose(double x, double y, double z, double roll, double pitch, double yaw) {
  return geometry::MakePose(geometry::RotationFromRpy(roll, pitch, yaw), {x, y, z});
}

bool BitIdentical(const Pose& a, const Pose& b) {
  return std::memcmp(a.matrix().data(), b.matrix().data(), sizeof(double) * 16) == 0;
}

void ExpectNear(const Pose& a, const Pose& b, double tolerance = kTolerance) {
  EXPECT_LE((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), tolerance) << "\n"
                                                                        << a.matrix() << "\nvs\n"
                                                                        << b.matrix();
}

double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(Motion, DefaultAndStaticHoldOnePose) {
  const Motion none;
  EXPECT_TRUE(none.IsStatic());
  ExpectNear(none.PoseAt(3.0), Pose::Identity(), 0.0);
  const Pose X = MakePose(1, 2, 3, 0.1, 0.2, 0.3);
  const Motion fixed = Motion::Static(X);
  EXPECT_TRUE(fixed.IsStatic());
  for (const double t : {-5.0, 0.0, 1.5, 1e9}) EXPECT_TRUE(BitIdentical(fixed.PoseAt(t), X));
}

TEST(Motion, WaypointsAreHitExactlyAtTheirTimes) {
  const std::vector<Motion::Waypoint> waypoints = {{0.0, MakePose(0, 0, 0, 0, 0, 0)},
                                                   {1.0, MakePose(1, 0, 0, 0, 0, 1.0)},
                                                   {3.0, MakePose(1, 2, 0, 0.5, 0, 1.0)}};
  const Motion motion = Motion::Waypoints(waypoints, false);
  EXPECT_FALSE(motion.IsStatic());
  for (const auto& w : waypoints) EXPECT_TRUE(BitIdentical(motion.PoseAt(w.time), w.pose));
}

TEST(Motion, WaypointsInterpolatePositionLinearlyAndRotationBySlerp) {
  const Pose a = MakePose(0, 0, 1, 0, 0, 0);
  const Pose b = MakePose(2, -4, 1, 0, 0, kPi / 2);
  const Motion motion = Motion::Waypoints({{1.0, a}, {3.0, b}}, false);
  for (const double s : {0.25, 0.5, 0.75}) {
    const Pose X = motion.PoseAt(1.0 + 2.0 * s);
    EXPECT_LT((X.translation() - Eigen::Vector3d(2 * s, -4 * s, 1)).norm(), kTolerance);
    // Slerp about z: the yaw grows linearly with time.
    ExpectNear(Pose(X.linear()), Pose(geometry::RotationFromRpy(0, 0, s * kPi / 2)));
  }
  // Held before the first and after the last waypoint.
  EXPECT_TRUE(BitIdentical(motion.PoseAt(0.0), a));
  EXPECT_TRUE(BitIdentical(motion.PoseAt(-10.0), a));
  EXPECT_TRUE(BitIdentical(motion.PoseAt(100.0), b));
}

TEST(Motion, SlerpTakesTheShortWayAndStaysOrthonormal) {
  // 350 degrees of yaw is -10 degrees: halfway is -5 degrees, not 175.
  const Motion motion = Motion::Waypoints(
      {{0.0, MakePose(0, 0, 0, 0, 0, 0)}, {1.0, MakePose(0, 0, 0, 0, 0, 350.0 * kPi / 180)}},
      false);
  const Eigen::Matrix3d R = motion.PoseAt(0.5).linear();
  EXPECT_NEAR(AngleBetween(R, geometry::RotationFromRpy(0, 0, -5.0 * kPi / 180)), 0.0, 1e-9);
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), kTolerance);
}

TEST(Motion, LoopWrapsAroundTheLastWaypointsTime) {
  const Pose a = MakePose(0, 0, 0, 0, 0, 0);
  const Pose b = MakePose(1, 0, 0, 0, 0, 0);
  const Pose c = MakePose(1, 1, 0, 0, 0, 0);
  const Motion motion = Motion::Waypoints({{0.0, a}, {1.0, b}, {4.0, c}}, true);
  // Period 4 s: t and t + 4k give the same bits (the wrap is exact for these times).
  for (const double t : {0.0, 0.5, 1.0, 2.5, 3.75}) {
    for (const int k : {-2, -1, 1, 3}) {
      EXPECT_TRUE(BitIdentical(motion.PoseAt(t + 4.0 * k), motion.PoseAt(t))) << t << " " << k;
    }
  }
  // At the period the script starts again: the first pose, not the last.
  EXPECT_TRUE(BitIdentical(motion.PoseAt(4.0), a));
  EXPECT_TRUE(BitIdentical(motion.PoseAt(8.0), a));
  // Just before the period: near the last pose.
  EXPECT_LT((motion.PoseAt(3.999999).translation() - c.translation()).norm(), 1e-5);
  // Without loop the last pose is held.
  const Motion held = Motion::Waypoints({{0.0, a}, {1.0, b}, {4.0, c}}, false);
  EXPECT_TRUE(BitIdentical(held.PoseAt(6.0), c));
}

TEST(Motion, ConstantVelocityTranslatesAndTurnsAboutWorldAxesThroughTheOrigin) {
  const Pose X0 = MakePose(1, 2, 3, 0.3, -0.2, 0.1);
  const Eigen::Vector3d v(0.5, -1.0, 0.25);
  const Eigen::Vector3d w(0.0, 0.0, kPi / 4);  // 45 deg/s about world z
  const Motion motion = Motion::ConstantVelocity(X0, v, w);
  EXPECT_FALSE(motion.IsStatic());
  ExpectNear(motion.PoseAt(0.0), X0);
  for (const double t : {0.5, 2.0, -1.0, 8.0}) {
    const Pose X = motion.PoseAt(t);
    EXPECT_LT((X.translation() - (X0.translation() + v * t)).norm(), kTolerance);
    const Eigen::Matrix3d expected =
        Eigen::AngleAxisd(t * kPi / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix() * X0.linear();
    EXPECT_NEAR(AngleBetween(X.linear(), expected), 0.0, 1e-9) << t;
  }
  // A full turn after 8 s.
  EXPECT_NEAR(AngleBetween(motion.PoseAt(8.0).linear(), X0.linear()), 0.0, 1e-9);
}

TEST(Motion, PoseIsAPureFunctionOfTime) {
  // Same t, same bits, whatever was evaluated before (no state, no accumulation).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> time(-20.0, 20.0);
  const std::vector<Motion> motions = {
      Motion::Waypoints({{0.0, MakePose(0, 0, 0, 0, 0, 0)},
                         {1.3, MakePose(1, 2, 3, 0.4, 0.1, -2.0)},
                         {2.9, MakePose(-1, 0, 2, 0, 1.0, 3.0)}},
                        true),
      Motion::ConstantVelocity(MakePose(1, 0, 0, 0, 0, 0), {0.1, 0.2, 0.3}, {0.3, -0.2, 1.0})};
  for (const Motion& motion : motions) {
    std::vector<double> times(50);
    for (double& t : times) t = time(rng);
    std::vector<Pose> first;
    for (const double t : times) first.push_back(motion.PoseAt(t));
    for (int i = static_cast<int>(times.size()) - 1; i >= 0; --i) {
      EXPECT_TRUE(BitIdentical(motion.PoseAt(times[i]), first[i])) << times[i];
    }
    const Motion copy = motion;
    EXPECT_TRUE(BitIdentical(copy.PoseAt(times[3]), first[3]));
  }
}

TEST(Motion, NonFiniteTimeGivesThePoseAtZeroWithoutThrowing) {
  const Motion motion = Motion::ConstantVelocity(MakePose(1, 0, 0, 0, 0, 0), {1, 0, 0}, {0, 0, 1});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(BitIdentical(motion.PoseAt(nan), motion.PoseAt(0.0)));
  EXPECT_TRUE(motion.PoseAt(std::numeric_limits<double>::infinity()).matrix().allFinite());
}

TEST(Motion, RejectsBadWaypointsAndVelocities) {
  const Pose I = Pose::Identity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Motion::Waypoints({}, false), InvalidArgument);
  EXPECT_THROW(Motion::Waypoints({{1.0, I}, {1.0, I}}, false), InvalidArgument);
  EXPECT_THROW(Motion::Waypoints({{2.0, I}, {1.0, I}}, false), InvalidArgument);
  EXPECT_THROW(Motion::Waypoints({{nan, I}}, false), InvalidArgument);
  EXPECT_THROW(Motion::Waypoints({{0.0, I}}, true), InvalidArgument);  // period 0
  Pose not_rigid = I;
  not_rigid.linear() *= 2.0;
  EXPECT_THROW(Motion::Waypoints({{0.0, not_rigid}}, false), InvalidArgument);
  EXPECT_THROW(Motion::Static(not_rigid), InvalidArgument);
  EXPECT_THROW(Motion::ConstantVelocity(I, {nan, 0, 0}, {0, 0, 0}), InvalidArgument);
  EXPECT_NO_THROW(Motion::Waypoints({{0.5, I}}, false));
  EXPECT_NO_THROW(Motion::Waypoints({{0.0, I}, {2.0, I}}, true));
}

}  // namespace
}  // namespace saccade::scene
