#include "saccade/geometry/pose.h"

#include <gtest/gtest.h>

#include <random>

namespace saccade::geometry {
namespace {

TEST(RotationFromRpy, FollowsRep103FixedAxes) {
  // Yaw of +90 deg turns x (forward) into y (left).
  const Eigen::Vector3d left = RotationFromRpy(0, 0, M_PI / 2) * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((left - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-15);
  // Pitch of +90 deg turns x (forward) into -z (down): nose down.
  const Eigen::Vector3d down = RotationFromRpy(0, M_PI / 2, 0) * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((down + Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-15);
}

TEST(RpyFromRotation, InvertsRotationFromRpy) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-M_PI + 1e-3, M_PI - 1e-3), pitch(-1.5, 1.5);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d rpy(angle(rng), pitch(rng), angle(rng));
    const Eigen::Vector3d back = RpyFromRotation(RotationFromRpy(rpy.x(), rpy.y(), rpy.z()));
    EXPECT_LT((back - rpy).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace saccade::geometry
