#include "saccade/head/kinematics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>
#include <string>

#include "saccade/core/error.h"

namespace saccade::head {
namespace {

using Eigen::Matrix4d;
using Eigen::Vector3d;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
// FK and the hand-multiplied paper matrices do the same few products of O(1) numbers in a
// different order: agreement to a few ulps of metres and of rotation entries.
constexpr double kMatrixTolerance = 1e-14;
// The brief's accuracy targets for IK: optical axes through the target to a nanometre, joint
// angles to a nanoradian (Newton itself reaches ~1e-15; these leave room for conditioning).
constexpr double kAxisDistanceTolerance = 1e-9;  // metres
constexpr double kAngleTolerance = 1e-9;         // radians
constexpr int kRandomCases = 500;

const std::string kPopeyePath = SACCADE_SOURCE_DIR "/robots/popeye.yaml";

HeadDescription MakeHead(const HeadGeometry& geometry, const geometry::Pose& X_WB) {
  const std::array<JointLimits, 4> limits{JointLimits{-90 * kDeg, 90 * kDeg, 5.0, 50.0},
                                          JointLimits{-45 * kDeg, 45 * kDeg, 5.0, 50.0},
                                          JointLimits{-45 * kDeg, 45 * kDeg, 10.0, 100.0},
                                          JointLimits{-45 * kDeg, 45 * kDeg, 10.0, 100.0}};
  const geometry::CameraModel camera(
      geometry::Intrinsics(1024, 768, 1290.32, 1290.32, 511.5, 383.5));
  return HeadDescription("test", geometry, limits, X_WB, camera, camera);
}

// A head placed and turned arbitrarily in the world, so that frame mix-ups show.
geometry::Pose TiltedBase() {
  return geometry::MakePose(geometry::RotationFromRpy(0.2, -0.15, 0.7), Vector3d(0.5, -0.3, 1.2));
}

// The paper's 4x4 matrices, written out as printed in appendix A.
Matrix4d PanMatrix(double pan) {  // {b} -> {n}: rotation about the paper's y (up) axis
  Matrix4d T;
  T << std::cos(pan), 0, std::sin(pan), 0,  //
      0, 1, 0, 0,                           //
      -std::sin(pan), 0, std::cos(pan), 0,  //
      0, 0, 0, 1;
  return T;
}
Matrix4d Eq4(double tilt, double D) {
  Matrix4d T;
  T << 1, 0, 0, 0,                            //
      0, std::cos(tilt), -std::sin(tilt), D,  //
      0, std::sin(tilt), std::cos(tilt), 0,   //
      0, 0, 0, 1;
  return T;
}
Matrix4d Eq5(double theta_l, double B) {
  Matrix4d T;
  T << std::cos(theta_l), 0, std::sin(theta_l), B,  //
      0, 1, 0, 0,                                   //
      -std::sin(theta_l), 0, std::cos(theta_l), 0,  //
      0, 0, 0, 1;
  return T;
}
Matrix4d Eq6(double theta_r, double B) {
  Matrix4d T;
  T << std::cos(theta_r), 0, std::sin(theta_r), -B,  //
      0, 1, 0, 0,                                    //
      -std::sin(theta_r), 0, std::cos(theta_r), 0,   //
      0, 0, 0, 1;
  return T;
}
Matrix4d Eq7or8(double delta) {
  Matrix4d T;
  T << -1, 0, 0, 0,    //
      0, -1, 0, 0,     //
      0, 0, 1, delta,  //
      0, 0, 0, 1;
  return T;
}
Matrix4d Eq9(double theta_r, double B) {
  Matrix4d T = Matrix4d::Identity();
  T(2, 3) = B / std::tan(theta_r);
  return T;
}
// The paper's axes (x left, y up, z forward) in the REP 103 base (x forward, y left, z up).
Matrix4d PaperAxesInBase() {
  Matrix4d T = Matrix4d::Zero();
  T(1, 0) = 1;  // paper x (left) = base y
  T(2, 1) = 1;  // paper y (up) = base z
  T(0, 2) = 1;  // paper z (forward) = base x
  T(3, 3) = 1;
  return T;
}

double MaxAbsDifference(const Matrix4d& a, const Matrix4d& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

// Distance from p to the optical axis (z) of camera X, and whether p is in front of it.
double AxisDistance(const geometry::Pose& X, const Vector3d& p) {
  const Vector3d axis = X.linear().col(2);
  return (p - X.translation()).cross(axis).norm();
}
bool InFront(const geometry::Pose& X, const Vector3d& p) {
  return (p - X.translation()).dot(X.linear().col(2)) > 0.0;
}

// Random joint states inside the limits whose optical axes meet in front: symmetric vergence
// between 0.5 and 45 degrees.
PopeyeJoints RandomSymmetric(std::mt19937& rng) {
  std::uniform_real_distribution<double> pan(-88 * kDeg, 88 * kDeg);
  std::uniform_real_distribution<double> tilt(-44 * kDeg, 44 * kDeg);
  std::uniform_real_distribution<double> vergence(0.5 * kDeg, 44 * kDeg);
  const double v = vergence(rng);
  return {pan(rng), tilt(rng), -v, v};
}

// ---------------------------------------------------------------------------------------
// Forward kinematics.

TEST(ForwardKinematicsTest, MatchesPaperMatricesEq4To9) {
  HeadGeometry geometry;
  geometry.B = 0.1;
  geometry.D = 0.07;  // eqs. 4, 7, 8 carry D and the deltas: test them non-zero too
  geometry.delta_l = 0.015;
  geometry.delta_r = -0.01;
  const HeadDescription head = MakeHead(geometry, TiltedBase());
  std::mt19937 rng(4);
  double worst = 0.0;
  for (int i = 0; i < kRandomCases; ++i) {
    const PopeyeJoints q = RandomSymmetric(rng);
    const HeadFrames f = ForwardKinematics(head, q);
    const Matrix4d W_b = head.X_WB().matrix() * PaperAxesInBase();
    const Matrix4d W_n = W_b * PanMatrix(q.pan);
    const Matrix4d W_c = W_n * Eq4(q.tilt, geometry.D);
    const Matrix4d W_l = W_c * Eq5(q.left, geometry.B);
    const Matrix4d W_r = W_c * Eq6(q.right, geometry.B);
    const Matrix4d W_caml = W_l * Eq7or8(geometry.delta_l);
    const Matrix4d W_camr = W_r * Eq7or8(geometry.delta_r);
    const std::pair<const geometry::Pose*, Matrix4d> pairs[] = {{&f.X_WN, W_n},
                                                                {&f.X_WC, W_c},
                                                                {&f.X_WL, W_l},
                                                                {&f.X_WR, W_r},
                                                                {&f.X_WCamLeft, W_caml},
                                                                {&f.X_WCamRight, W_camr},
                                                                {&f.X_WB, head.X_WB().matrix()}};
    for (const auto& [pose, expected] : pairs) {
      const double difference = MaxAbsDifference(pose->matrix(), expected);
      worst = std::max(worst, difference);
      ASSERT_LE(difference, kMatrixTolerance) << "case " << i;
    }
    // Eq. 9: {f} is {c} moved B / tan(theta_r) along z (symmetric vergence).
    ASSERT_TRUE(f.p_WFixation.has_value());
    const Vector3d expected_f = (W_c * Eq9(q.right, geometry.B)).block<3, 1>(0, 3);
    ASSERT_LE((*f.p_WFixation - expected_f).norm(), kMatrixTolerance) << "case " << i;
  }
  std::cout << "[ stats    ] FK vs paper matrices: worst entry difference " << worst << "\n";
}

TEST(ForwardKinematicsTest, FixationMatchesEq10InPaperBaseFrame) {
  const HeadDescription head = MakeHead(HeadGeometry{}, TiltedBase());  // D = H = 0 as in eq. 10
  const double B = head.geometry().B;
  std::mt19937 rng(10);
  for (int i = 0; i < kRandomCases; ++i) {
    const PopeyeJoints q = RandomSymmetric(rng);
    const HeadFrames f = ForwardKinematics(head, q);
    ASSERT_TRUE(f.p_WFixation.has_value());
    const double t = std::tan(q.right);
    const Eigen::Vector4d p_b(B * std::sin(q.pan) * std::cos(q.tilt) / t, -B * std::sin(q.tilt) / t,
                              B * std::cos(q.pan) * std::cos(q.tilt) / t, 1.0);
    const Vector3d expected = (head.X_WB().matrix() * PaperAxesInBase() * p_b).head<3>();
    // Relative: eq. 10's distances reach B / tan(0.5 deg) = 11 m.
    ASSERT_LE((*f.p_WFixation - expected).norm(), kMatrixTolerance * (1.0 + expected.norm()))
        << "case " << i;
  }
}

TEST(ForwardKinematicsTest, SignConventionsOfTheHeader) {
  const HeadDescription head = MakeHead(HeadGeometry{}, geometry::Pose::Identity());
  const auto fixation_in_base = [&](const PopeyeJoints& q) {
    const auto p = ForwardKinematics(head, q).p_WFixation;
    EXPECT_TRUE(p.has_value());
    return p.value_or(Vector3d::Zero());
  };
  const double v = 10 * kDeg;  // converging: left < 0 < right
  const Vector3d ahead = fixation_in_base({0, 0, -v, v});
  EXPECT_GT(ahead.x(), 0.5);  // in front (REP 103 x forward)
  EXPECT_NEAR(ahead.y(), 0.0, kMatrixTolerance);
  EXPECT_NEAR(ahead.z(), 0.0, kMatrixTolerance);
  EXPECT_GT(fixation_in_base({0.3, 0, -v, v}).y(), 0.1);   // pan > 0 looks left (+y)
  EXPECT_LT(fixation_in_base({0, 0.3, -v, v}).z(), -0.1);  // tilt > 0 looks down (-z)
  // Both eyes turned left (> 0) with the left one more: the axes diverge, no fixation.
  EXPECT_FALSE(ForwardKinematics(head, {0, 0, v, -v}).p_WFixation.has_value());
  EXPECT_FALSE(ForwardKinematics(head, {0, 0, 0, 0}).p_WFixation.has_value());  // parallel
  EXPECT_FALSE(ForwardKinematics(head, {0, 0, 0.2, 0.2}).p_WFixation.has_value());
  // The left camera sits on the base's +y side, and its optical x axis points right (-y).
  const HeadFrames f = ForwardKinematics(head, {});
  EXPECT_NEAR(f.X_WCamLeft.translation().y(), head.geometry().B, kMatrixTolerance);
  EXPECT_TRUE(f.X_WCamLeft.linear().col(0).isApprox(Vector3d(0, -1, 0)));
  EXPECT_TRUE(f.X_WCamLeft.linear().col(1).isApprox(Vector3d(0, 0, -1)));  // y down
  EXPECT_TRUE(f.X_WCamLeft.linear().col(2).isApprox(Vector3d(1, 0, 0)));   // z forward
}

TEST(ForwardKinematicsTest, IndependentEyesMeetWhereBothAxesPass) {
  HeadGeometry geometry;
  geometry.D = 0.05;
  geometry.H = 0.03;
  geometry.delta_l = 0.02;
  geometry.delta_r = 0.01;
  const HeadDescription head = MakeHead(geometry, TiltedBase());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-40 * kDeg, 40 * kDeg);
  for (int i = 0; i < kRandomCases; ++i) {
    const PopeyeJoints q{angle(rng), angle(rng), angle(rng), angle(rng)};
    const HeadFrames f = ForwardKinematics(head, q);
    if (!f.p_WFixation) continue;
    EXPECT_LT(q.left, q.right);  // only converging eyes meet in front
    EXPECT_LE(AxisDistance(f.X_WCamLeft, *f.p_WFixation), kAxisDistanceTolerance);
    EXPECT_LE(AxisDistance(f.X_WCamRight, *f.p_WFixation), kAxisDistanceTolerance);
    EXPECT_TRUE(InFront(f.X_WCamLeft, *f.p_WFixation));
    EXPECT_TRUE(InFront(f.X_WCamRight, *f.p_WFixation));
  }
}

TEST(ForwardKinematicsTest, HeightHTurnsWithTilt) {
  HeadGeometry geometry;
  geometry.H = 0.04;
  const HeadDescription head = MakeHead(geometry, geometry::Pose::Identity());
  const double tilt = 0.3;
  const HeadFrames f = ForwardKinematics(head, {0, tilt, 0, 0});
  // {c} is H along the tilted up axis: up (z) cos(tilt), forward (x) sin(tilt) when looking down.
  EXPECT_TRUE(f.X_WC.translation().isApprox(
      Vector3d(geometry.H * std::sin(tilt), 0, geometry.H * std::cos(tilt))));
}

// ---------------------------------------------------------------------------------------
// Inverse kinematics.

TEST(ForwardKinematicsTest, AxisErrorsAreTheOpticalAxesAnglesToThePoint) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  // Parallel eyes: a point 2 m along the left axis is on it; the right axis, parallel and one
  // baseline (2 B, appendix A) away, misses it by atan(2 B / 2 m).
  const HeadFrames f = ForwardKinematics(head, PopeyeJoints{});
  const Vector3d p = f.X_WCamLeft * Vector3d(0.0, 0.0, 2.0);
  const double baseline = (f.X_WCamLeft.translation() - f.X_WCamRight.translation()).norm();
  EXPECT_NEAR(baseline, 2.0 * head.geometry().B, 1e-12);  // delta_l = delta_r = 0
  const Eigen::Vector2d e = AxisErrors(head, PopeyeJoints{}, p);
  EXPECT_LT(e[0], 1e-12);
  EXPECT_NEAR(e[1], std::atan2(baseline, 2.0), 1e-12);
  // A fixated point: both zero (to the solver's 1e-9 rad); a point behind: near pi.
  const PopeyeJoints verged{0.1, -0.05, -0.03, 0.03};
  const Vector3d fixated = ForwardKinematics(head, verged).p_WFixation.value();
  EXPECT_LT(AxisErrors(head, verged, fixated).maxCoeff(), 1e-9);
  const Vector3d behind = f.X_WCamLeft * Vector3d(0.0, 0.0, -2.0);
  EXPECT_NEAR(AxisErrors(head, PopeyeJoints{}, behind)[0], M_PI, 1e-9);
}

TEST(InverseKinematicsTest, PopeyeRandomTargetsAreFixatedExactly) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  std::mt19937 rng(2024);
  double worst_axis = 0.0;
  double worst_closed_form = 0.0;
  double worst_roundtrip = 0.0;
  int total_iterations = 0;
  int max_iterations = 0;
  for (int i = 0; i < kRandomCases; ++i) {
    const PopeyeJoints truth = RandomSymmetric(rng);
    const Vector3d target = ForwardKinematics(head, truth).p_WFixation.value();
    const IkResult ik = SolveFixation(head, target);
    ASSERT_TRUE(ik.reachable()) << "case " << i << ": " << ik.message;
    ASSERT_TRUE(head.WithinLimits(ik.joints));
    EXPECT_EQ(ik.joints.left, -ik.joints.right) << "symmetric vergence is exact";
    const HeadFrames f = ForwardKinematics(head, ik.joints);
    for (const auto* X : {&f.X_WCamLeft, &f.X_WCamRight}) {
      worst_axis = std::max(worst_axis, AxisDistance(*X, target));
      ASSERT_LE(AxisDistance(*X, target), kAxisDistanceTolerance) << "case " << i;
      ASSERT_TRUE(InFront(*X, target));
    }
    EXPECT_LE(ik.axis_error, kAngleTolerance);
    // FK(IK(target)) is the target.
    ASSERT_TRUE(f.p_WFixation.has_value());
    worst_roundtrip = std::max(worst_roundtrip, (*f.p_WFixation - target).norm());
    ASSERT_LE((*f.p_WFixation - target).norm(), kAxisDistanceTolerance) << "case " << i;
    // The closed form of eqs. 10-13 agrees, and both recover the joints that made the target.
    const IkResult closed = SolveFixationClosedForm(head, target);
    ASSERT_TRUE(closed.reachable()) << closed.message;
    for (const Joint joint : kAllJoints) {
      worst_closed_form =
          std::max(worst_closed_form, std::abs(closed.joints[joint] - ik.joints[joint]));
      ASSERT_NEAR(closed.joints[joint], ik.joints[joint], kAngleTolerance) << JointName(joint);
      ASSERT_NEAR(truth[joint], ik.joints[joint], kAngleTolerance) << JointName(joint);
    }
    total_iterations += ik.iterations;
    max_iterations = std::max(max_iterations, ik.iterations);
  }
  std::cout << "[ stats    ] popeye: worst axis distance " << worst_axis << " m, worst FK(IK) "
            << worst_roundtrip << " m, worst closed form vs Newton " << worst_closed_form
            << " rad, Newton iterations mean " << double(total_iterations) / kRandomCases << " max "
            << max_iterations << "\n";
}

TEST(InverseKinematicsTest, ClosedFormMatchesEq10To13Literally) {
  // A target written with eq. 10 from chosen angles comes back through eqs. 11-13.
  const HeadDescription head = MakeHead(HeadGeometry{}, geometry::Pose::Identity());
  const double B = head.geometry().B;
  const double pan = 30 * kDeg, tilt = -20 * kDeg, right = 5 * kDeg;
  const double t = std::tan(right);
  const Vector3d p_b(B * std::sin(pan) * std::cos(tilt) / t, -B * std::sin(tilt) / t,
                     B * std::cos(pan) * std::cos(tilt) / t);  // paper axes
  const Vector3d p_W(p_b.z(), p_b.x(), p_b.y());               // REP 103 base = world here
  const IkResult ik = SolveFixationClosedForm(head, p_W);
  ASSERT_TRUE(ik.reachable()) << ik.message;
  EXPECT_NEAR(ik.joints.pan, pan, kAngleTolerance);
  EXPECT_NEAR(ik.joints.tilt, tilt, kAngleTolerance);
  EXPECT_NEAR(ik.joints.right, right, kAngleTolerance);
  EXPECT_EQ(ik.joints.left, -ik.joints.right);
}

TEST(InverseKinematicsTest, GeneralGeometryStillPutsBothAxesThroughTheTarget) {
  HeadGeometry geometry;
  geometry.B = 0.08;
  geometry.D = 0.06;
  geometry.H = 0.035;
  geometry.delta_l = 0.02;
  geometry.delta_r = 0.012;
  const HeadDescription head = MakeHead(geometry, TiltedBase());
  EXPECT_THROW(SolveFixationClosedForm(head, Vector3d(2, 0, 1)), InvalidArgument);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> seed_angle(-0.5, 0.5);
  double worst_axis = 0.0;
  int total_iterations = 0;
  for (int i = 0; i < kRandomCases; ++i) {
    const PopeyeJoints truth = RandomSymmetric(rng);
    const auto target = ForwardKinematics(head, truth).p_WFixation;
    ASSERT_TRUE(target.has_value());
    IkOptions options;
    if (i % 2 == 1) {  // half from the zero seed, half from random seeds
      options.seed = {seed_angle(rng), seed_angle(rng), seed_angle(rng), seed_angle(rng)};
    }
    const IkResult ik = SolveFixation(head, *target, options);
    ASSERT_TRUE(ik.reachable()) << "case " << i << ": " << ik.message;
    ASSERT_TRUE(head.WithinLimits(ik.joints));
    EXPECT_EQ(ik.joints.left, -ik.joints.right);
    const HeadFrames f = ForwardKinematics(head, ik.joints);
    for (const auto* X : {&f.X_WCamLeft, &f.X_WCamRight}) {
      worst_axis = std::max(worst_axis, AxisDistance(*X, *target));
      ASSERT_LE(AxisDistance(*X, *target), kAxisDistanceTolerance) << "case " << i;
      ASSERT_TRUE(InFront(*X, *target));
    }
    ASSERT_TRUE(f.p_WFixation.has_value());
    ASSERT_LE((*f.p_WFixation - *target).norm(), kAxisDistanceTolerance);
    for (const Joint joint : kAllJoints) {
      ASSERT_NEAR(truth[joint], ik.joints[joint], kAngleTolerance) << JointName(joint);
    }
    total_iterations += ik.iterations;
  }
  std::cout << "[ stats    ] D, H, deltas != 0: worst axis distance " << worst_axis
            << " m, Newton iterations mean " << double(total_iterations) / kRandomCases << "\n";
}

TEST(InverseKinematicsTest, IndependentModeKeepsPanAndFixates) {
  HeadGeometry geometry;
  geometry.D = 0.04;
  geometry.H = 0.02;
  geometry.delta_l = 0.01;
  geometry.delta_r = 0.02;
  for (const HeadGeometry& g : {HeadGeometry{}, geometry}) {
    const HeadDescription head = MakeHead(g, TiltedBase());
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> pan(-80 * kDeg, 80 * kDeg);
    std::uniform_real_distribution<double> tilt(-40 * kDeg, 40 * kDeg);
    std::uniform_real_distribution<double> eye(-40 * kDeg, 40 * kDeg);
    double worst_axis = 0.0;
    int cases = 0;
    while (cases < kRandomCases) {
      PopeyeJoints truth{pan(rng), tilt(rng), eye(rng), eye(rng)};
      if (truth.right - truth.left < 0.5 * kDeg) continue;  // axes must meet in front
      const auto target = ForwardKinematics(head, truth).p_WFixation;
      if (!target) continue;
      ++cases;
      IkOptions options;
      options.mode = VergenceMode::kIndependent;
      options.seed.pan = truth.pan;
      const IkResult ik = SolveFixation(head, *target, options);
      ASSERT_TRUE(ik.reachable()) << ik.message;
      EXPECT_EQ(ik.joints.pan, truth.pan) << "pan is the seed's, unchanged";
      ASSERT_TRUE(head.WithinLimits(ik.joints));
      const HeadFrames f = ForwardKinematics(head, ik.joints);
      for (const auto* X : {&f.X_WCamLeft, &f.X_WCamRight}) {
        worst_axis = std::max(worst_axis, AxisDistance(*X, *target));
        ASSERT_LE(AxisDistance(*X, *target), kAxisDistanceTolerance);
        ASSERT_TRUE(InFront(*X, *target));
      }
      ASSERT_TRUE(f.p_WFixation.has_value());
      ASSERT_LE((*f.p_WFixation - *target).norm(), kAxisDistanceTolerance);
      for (const Joint joint : kAllJoints) {
        ASSERT_NEAR(truth[joint], ik.joints[joint], kAngleTolerance) << JointName(joint);
      }
    }
    std::cout << "[ stats    ] independent (D = " << g.D << "): worst axis distance " << worst_axis
              << " m\n";
  }
}

// Checks an unreachable result: flagged, explained naming `joint`, inside the limits.
void ExpectUnreachable(const HeadDescription& head, const IkResult& ik, Reachability why,
                       const std::string& joint) {
  EXPECT_FALSE(ik.reachable());
  EXPECT_EQ(ik.reachability, why) << ToString(ik.reachability) << ": " << ik.message;
  EXPECT_NE(ik.message.find(joint), std::string::npos) << ik.message;
  EXPECT_TRUE(head.WithinLimits(ik.joints)) << ik.message;
  EXPECT_GT(ik.axis_error, 0.0);
}

TEST(InverseKinematicsTest, TargetBehindTheHeadIsFlaggedAndClamped) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  // 2 m behind the head and a little to its left (REP 103 base: x forward, y left, z up).
  const Vector3d target = head.X_WB() * Vector3d(-2.0, 0.5, 0.0);
  for (const IkResult& ik : {SolveFixation(head, target), SolveFixationClosedForm(head, target)}) {
    ExpectUnreachable(head, ik, Reachability::kBehind, "pan");
    EXPECT_NEAR(ik.joints.pan, head.limits(Joint::kPan).max, kAngleTolerance);  // clamped left
    EXPECT_EQ(ik.joints.left, -ik.joints.right);
    EXPECT_NE(ik.message.find("behind"), std::string::npos) << ik.message;
  }
  IkOptions independent;
  independent.mode = VergenceMode::kIndependent;
  const IkResult ik = SolveFixation(head, target, independent);
  ExpectUnreachable(head, ik, Reachability::kBehind, "left");
  EXPECT_EQ(ik.joints.pan, 0.0);
}

TEST(InverseKinematicsTest, TargetTooCloseIsFlaggedAndClamped) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  // 5 cm ahead: vergence atan(0.1 / 0.05) = 63 deg, beyond the eyes' 45.
  const Vector3d target = head.X_WB() * Vector3d(0.05, 0.0, 0.0);
  for (const IkResult& ik : {SolveFixation(head, target), SolveFixationClosedForm(head, target)}) {
    ExpectUnreachable(head, ik, Reachability::kTooClose, "right");
    EXPECT_NE(ik.message.find("left"), std::string::npos) << ik.message;
    EXPECT_NEAR(ik.joints.right, head.limits(Joint::kRight).max, kAngleTolerance);
    EXPECT_EQ(ik.joints.left, -ik.joints.right);
    EXPECT_NEAR(ik.joints.pan, 0.0, kAngleTolerance);  // pan and tilt are still exact
    EXPECT_NEAR(ik.joints.tilt, 0.0, kAngleTolerance);
  }
  IkOptions independent;
  independent.mode = VergenceMode::kIndependent;
  ExpectUnreachable(head, SolveFixation(head, target, independent), Reachability::kTooClose,
                    "right");
}

TEST(InverseKinematicsTest, TargetBeyondTiltLimitIsFlaggedAndClamped) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  // 1 m ahead, 30 deg to the left, 60 deg down: tilt limit 45 deg.
  const double pan = 30 * kDeg, down = 60 * kDeg;
  const Vector3d p_B(std::cos(down) * std::cos(pan), std::cos(down) * std::sin(pan),
                     -std::sin(down));
  const Vector3d target = head.X_WB() * p_B;
  IkOptions independent;
  independent.mode = VergenceMode::kIndependent;
  independent.seed.pan = pan;
  for (const IkResult& ik : {SolveFixation(head, target), SolveFixationClosedForm(head, target),
                             SolveFixation(head, target, independent)}) {
    ExpectUnreachable(head, ik, Reachability::kJointLimit, "tilt");
    EXPECT_NE(ik.message.find("60.000 deg"), std::string::npos) << ik.message;
    EXPECT_NEAR(ik.joints.tilt, head.limits(Joint::kTilt).max, kAngleTolerance);
    EXPECT_NEAR(ik.joints.pan, pan, kAngleTolerance);  // the other joints stay exact
  }
}

TEST(InverseKinematicsTest, PanSeedOutsideLimitsIsReportedInIndependentMode) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  IkOptions options;
  options.mode = VergenceMode::kIndependent;
  options.seed.pan = 80 * kDeg;  // inside
  const Vector3d target = head.X_WB() * Vector3d(1.0, 1.0, 0.0);
  EXPECT_TRUE(SolveFixation(head, target, options).reachable());
  options.seed.pan = 1.7;  // outside +-90 deg: clamped, never silently
  const IkResult ik = SolveFixation(head, target, options);
  EXPECT_FALSE(ik.reachable());
  EXPECT_NE(ik.message.find("pan"), std::string::npos) << ik.message;
  EXPECT_EQ(ik.joints.pan, head.limits(Joint::kPan).max);
  EXPECT_TRUE(head.WithinLimits(ik.joints));
}

TEST(InverseKinematicsTest, DegenerateTargetsAreFlagged) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  const Vector3d cyclopean = head.X_WB().translation();  // D = H = 0: the base origin
  ExpectUnreachable(head, SolveFixation(head, cyclopean), Reachability::kDegenerate, "cyclopean");
  ExpectUnreachable(head, SolveFixationClosedForm(head, cyclopean), Reachability::kDegenerate,
                    "cyclopean");
  IkOptions independent;
  independent.mode = VergenceMode::kIndependent;
  const Vector3d left_eye = head.X_WB() * Vector3d(0.0, head.geometry().B, 0.0);
  ExpectUnreachable(head, SolveFixation(head, left_eye, independent), Reachability::kDegenerate,
                    "eye");
  // Straight above the head: pan is free (kept from the seed), tilt would need -90 deg.
  const IkResult above = SolveFixation(head, head.X_WB() * Vector3d(0.0, 0.0, 1.0));
  ExpectUnreachable(head, above, Reachability::kJointLimit, "tilt");
}

TEST(InverseKinematicsTest, NonFiniteTargetThrows) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  const Vector3d nan(std::nan(""), 0.0, 1.0);
  EXPECT_THROW(SolveFixation(head, nan), InvalidArgument);
  EXPECT_THROW(SolveFixationClosedForm(head, nan), InvalidArgument);
  EXPECT_THROW(SolveFixation(head, Vector3d(INFINITY, 0, 0)), InvalidArgument);
  // A far but finite target never throws.
  const IkResult far = SolveFixation(head, head.X_WB() * Vector3d(1e6, 0, 0));
  EXPECT_TRUE(far.reachable()) << far.message;
}

TEST(InverseKinematicsTest, ReachabilityNames) {
  EXPECT_STREQ(ToString(Reachability::kReachable), "reachable");
  EXPECT_STREQ(ToString(Reachability::kBehind), "behind");
  EXPECT_STREQ(ToString(Reachability::kTooClose), "too close");
  EXPECT_STREQ(ToString(Reachability::kJointLimit), "joint limit");
  EXPECT_STREQ(ToString(Reachability::kDegenerate), "degenerate");
}

// Every target in a box around the head: never throws, always within limits, and the flag is
// honest: reachable means both axes pass through the target.
TEST(InverseKinematicsTest, AnyTargetGivesAnHonestResultWithinLimits) {
  HeadGeometry geometry;
  geometry.D = 0.05;
  geometry.H = 0.03;
  geometry.delta_l = 0.01;
  geometry.delta_r = 0.01;
  const HeadDescription head = MakeHead(geometry, TiltedBase());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5);
  int reachable = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vector3d target =
        head.X_WB() * Vector3d(coordinate(rng), coordinate(rng), coordinate(rng));
    for (const VergenceMode mode : {VergenceMode::kSymmetric, VergenceMode::kIndependent}) {
      IkOptions options;
      options.mode = mode;
      const IkResult ik = SolveFixation(head, target, options);
      ASSERT_TRUE(head.WithinLimits(ik.joints)) << ik.message;
      if (ik.reachable()) {
        ++reachable;
        EXPECT_TRUE(ik.message.empty());
        const HeadFrames f = ForwardKinematics(head, ik.joints);
        ASSERT_LE(AxisDistance(f.X_WCamLeft, target), kAxisDistanceTolerance);
        ASSERT_LE(AxisDistance(f.X_WCamRight, target), kAxisDistanceTolerance);
      } else {
        EXPECT_FALSE(ik.message.empty());
      }
    }
  }
  EXPECT_GT(reachable, 200);  // the box is not all out of reach
}

}  // namespace
}  // namespace saccade::head
