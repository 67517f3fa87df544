#include "saccade/head/fixation.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <random>

#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"

namespace saccade::head {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;
using Eigen::VectorXd;
using geometry::Pose;

// The bound on the axes through the target and on the agreement with appendix A: the
// solver converges to |u - e_z| ~ 1e-13, so both hold with margin.
constexpr double kAxisTolerance = 1e-9;
constexpr double kAppendixATolerance = 1e-9;
// Random targets per head: 10,000 in the release build, whose figures the issue asked for;
// 2,000 under AddressSanitizer (CI's second run, there for memory errors, not the statistics),
// where the humanoid's 10,000 took 130 s of CI's 2 cores against 5 s in the release build.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kTargets = 2000;
#else
constexpr int kTargets = 10000;
#endif

const fs::path kSource = SACCADE_SOURCE_DIR;

const std::vector<std::string> kHeadFiles = {
    "robots/popeye.yaml", "robots/popeye_urdf.yaml", "robots/humanoid.yaml",
    "robots/pan_tilt_vergence.yaml", "robots/pan_tilt_fixed.yaml"};

// The angle between the mid-axis (midway between the cameras, fixation.h) and the target.
double MidAxisError(const HeadModel& head, const VectorXd& q, const Vector3d& p_W) {
  std::vector<Pose> X_WL;
  head.ForwardKinematics(q, &X_WL);
  const Pose left = head.CameraPose(0, X_WL);
  const Pose right = head.CameraPose(1, X_WL);
  const Eigen::Quaterniond mid =
      Eigen::Quaterniond(left.linear()).slerp(0.5, Eigen::Quaterniond(right.linear()));
  const Vector3d axis = mid.toRotationMatrix().col(2);
  const Vector3d t = p_W - 0.5 * (left.translation() + right.translation());
  return std::atan2(axis.cross(t).norm(), axis.dot(t));
}

// A target: mostly ahead of the head, some anywhere (behind, above, at the eyes).
Vector3d RandomTarget(const HeadModel& head, std::mt19937_64* random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Vector3d p_B =
      unit(*random) < 0.8
          ? Vector3d(0.2 + 4.8 * unit(*random), -3 + 6 * unit(*random), -1.5 + 3 * unit(*random))
          : Vector3d(-3 + 6 * unit(*random), -3 + 6 * unit(*random), -3 + 6 * unit(*random));
  return head.X_WB() * p_B;
}

class EveryHead : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryHead, RandomTargetsAreFixatedOrRefusedWithAReasonNeverANan) {
  const HeadModel head = HeadModel::FromFile(kSource / GetParam());
  FixationSolver solver(head);
  std::mt19937_64 random(2042);
  int reachable = 0;
  int ahead = 0;
  int ahead_reachable = 0;
  double worst = 0.0;
  for (int n = 0; n < kTargets; ++n) {
    const Vector3d p_W = RandomTarget(head, &random);
    const FixationResult result = solver.Solve(p_W);
    ASSERT_TRUE(result.joints.allFinite()) << p_W.transpose();
    ASSERT_TRUE(head.WithinLimits(result.joints)) << p_W.transpose();
    ASSERT_TRUE(std::isfinite(result.axis_error));
    // Straight ahead of the home posture's cameras, within 10 degrees, 0.5 to 5 m: every
    // shipped head can look there.
    const Vector3d p_B = head.X_WB().inverse() * p_W;
    const bool straight_ahead =
        p_B.x() > 0.5 && p_B.norm() < 5.0 && std::hypot(p_B.y(), p_B.z() - 0.2) < 0.17 * p_B.x();
    ahead += straight_ahead;
    if (!result.reachable()) {
      EXPECT_FALSE(result.message.empty());
      EXPECT_FALSE(straight_ahead)
          << GetParam() << ": " << p_W.transpose() << ": " << result.message;
      continue;
    }
    ++reachable;
    ahead_reachable += straight_ahead;
    // Measured here, independently of the solver's own residual.
    const double error = result.mid_axis ? MidAxisError(head, result.joints, p_W)
                                         : AxisErrors(head, result.joints, p_W).maxCoeff();
    worst = std::max(worst, error);
    ASSERT_LE(error, kAxisTolerance) << GetParam() << ": " << p_W.transpose();
  }
  EXPECT_GT(ahead, kTargets / 100);
  EXPECT_EQ(ahead_reachable, ahead);
  EXPECT_GT(reachable, kTargets / 4) << GetParam();
  RecordProperty("reachable", reachable);
  RecordProperty("worst_axis_error", fmt::format("{:.3g}", worst));
}

INSTANTIATE_TEST_SUITE_P(Shipped, EveryHead, ::testing::ValuesIn(kHeadFiles),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return fs::path(info.param).stem().string();
                         });

TEST(Fixation, OnPopeyeTheGeneralSolverGivesAppendixAsSolution) {
  const HeadDescription legacy = HeadDescription::FromYamlFile(kSource / "robots/popeye.yaml");
  for (const char* file : {"robots/popeye.yaml", "robots/popeye_urdf.yaml"}) {
    const HeadModel head = HeadModel::FromFile(kSource / file);
    FixationSolver solver(head);
    std::mt19937_64 random(9);
    int compared = 0;
    double worst = 0.0;
    for (int n = 0; n < 2000; ++n) {
      const Vector3d p_W = RandomTarget(head, &random);
      const IkResult closed = SolveFixationClosedForm(legacy, p_W);
      const FixationResult general = solver.Solve(p_W);
      if (!closed.reachable()) continue;
      ASSERT_TRUE(general.reachable()) << file << ": " << p_W.transpose() << general.message;
      const Eigen::Vector4d expected(closed.joints.pan, closed.joints.tilt, closed.joints.left,
                                     closed.joints.right);
      worst = std::max(worst, (general.joints - VectorXd(expected)).lpNorm<Eigen::Infinity>());
      ++compared;
    }
    EXPECT_GT(compared, 1000) << file;
    EXPECT_LE(worst, kAppendixATolerance) << file;
  }
}

TEST(Fixation, TheRuleHoldsJointsAndWeightsShareTheGazeBetweenNeckAndEyes) {
  const HeadModel head = HeadModel::FromFile(kSource / "robots/humanoid.yaml");
  const int roll = head.FindJoint("neck_roll");
  const int yaw = head.FindJoint("neck_yaw");
  const int left = head.FindJoint("left_eye_pan");
  ASSERT_GE(roll, 0);
  FixationOptions options;
  options.seed = head.HomePosture();
  options.seed[roll] = 0.1;  // held where it is
  const Vector3d p_W = head.X_WB() * Vector3d(2.0, 0.8, 0.3);
  const FixationResult result = SolveFixation(head, p_W, options);
  ASSERT_TRUE(result.reachable()) << result.message;
  EXPECT_EQ(result.joints[roll], 0.1);
  // The neck (weight 4) turns less than the eyes (weight 1) towards the target on the left,
  // but both turn.
  EXPECT_GT(result.joints[yaw], 0.0);
  EXPECT_GT(result.joints[left], 0.0);
  EXPECT_LT(result.joints[yaw], result.joints[left] + 0.3);
}

TEST(Fixation, OneVergenceMotorTurnsBothEyesThroughTheMimicJoint) {
  const HeadModel head = HeadModel::FromFile(kSource / "robots/pan_tilt_vergence.yaml");
  ASSERT_EQ(head.num_joints(), 3);
  const Vector3d p_W = head.X_WB() * Vector3d(0.8, -0.2, 0.1);
  const FixationResult result = SolveFixation(head, p_W);
  ASSERT_TRUE(result.reachable()) << result.message;
  EXPECT_FALSE(result.mid_axis);
  EXPECT_GT(result.joints[head.FindJoint("vergence")], 0.0);  // converging on a near target
  EXPECT_LE(AxisErrors(head, result.joints, p_W).maxCoeff(), kAxisTolerance);
}

TEST(Fixation, AFixedCameraPairPointsItsMidAxis) {
  const HeadModel head = HeadModel::FromFile(kSource / "robots/pan_tilt_fixed.yaml");
  FixationSolver solver(head);
  EXPECT_FALSE(solver.can_verge());
  const Vector3d p_W = head.X_WB() * Vector3d(2.0, 0.5, -0.2);
  const FixationResult result = solver.Solve(p_W);
  ASSERT_TRUE(result.reachable()) << result.message;
  EXPECT_TRUE(result.mid_axis);
  EXPECT_LE(MidAxisError(head, result.joints, p_W), kAxisTolerance);
  // Each camera alone is off by the half-baseline's angle, not fixating.
  EXPECT_GT(AxisErrors(head, result.joints, p_W).minCoeff(), 1e-3);
}

TEST(Fixation, ATargetBehindOrBeyondTheLimitsIsRefusedWithTheReason) {
  const HeadModel head = HeadModel::FromFile(kSource / "robots/humanoid.yaml");
  const FixationResult behind = SolveFixation(head, head.X_WB() * Vector3d(-2.0, 0.1, 0.2));
  EXPECT_EQ(behind.reachability, Reachability::kBehind);
  EXPECT_THAT(behind.message, ::testing::HasSubstr("behind the head"));
  const FixationResult above = SolveFixation(head, head.X_WB() * Vector3d(0.3, 0.0, 3.0));
  EXPECT_EQ(above.reachability, Reachability::kJointLimit);
  EXPECT_THAT(above.message, ::testing::HasSubstr("would leave its limits"));
  EXPECT_THROW(SolveFixation(head, Vector3d(std::nan(""), 0, 0)), InvalidArgument);
}

}  // namespace
}  // namespace saccade::head
