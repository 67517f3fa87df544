#include "saccade/head/kinematic_tree.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "saccade/core/error.h"

namespace saccade::head {
namespace {

using geometry::Pose;
using ::testing::AllOf;
using ::testing::HasSubstr;

// Hand-computed chains: a few products of exact rotations, rounding ~1e-16.
constexpr double kExactTolerance = 1e-14;
// Central differences with step 1e-6 on functions with derivatives of order 1: truncation
// ~1e-12, rounding ~1e-16 / 1e-6 = 1e-10.
constexpr double kFiniteDifferenceTolerance = 1e-8;

Pose Offset(double x, double y, double z) {
  Pose X = Pose::Identity();
  X.translation() = Eigen::Vector3d(x, y, z);
  return X;
}

JointSpec Revolute(const std::string& name, const std::string& parent, const std::string& child,
                   const Pose& X_PJ, const Eigen::Vector3d& axis) {
  JointSpec j;
  j.name = name;
  j.type = JointType::kRevolute;
  j.parent = parent;
  j.child = child;
  j.X_PJ = X_PJ;
  j.axis = axis;
  j.lower = -2.0;
  j.upper = 2.0;
  return j;
}

// A pan-tilt neck with two eyes, the right one a mimic of the left (one vergence motor).
KinematicTree PanTiltVergence() {
  std::vector<JointSpec> joints = {
      Revolute("pan", "base", "neck", Pose::Identity(), Eigen::Vector3d::UnitZ()),
      Revolute("tilt", "neck", "head", Offset(0, 0, 0.1), Eigen::Vector3d::UnitY()),
      Revolute("vergence", "head", "left_eye", Offset(0, 0.06, 0), -Eigen::Vector3d::UnitZ()),
      Revolute("right_vergence", "head", "right_eye", Offset(0, -0.06, 0),
               -Eigen::Vector3d::UnitZ())};
  joints[3].mimic = MimicSpec{"vergence", -1.0, 0.0};
  return KinematicTree::Build({"base", "neck", "head", "left_eye", "right_eye"}, joints, "test");
}

TEST(KinematicTree, ForwardKinematicsOfAPanTiltVergenceHeadIsTheHandComputedChain) {
  const KinematicTree tree = PanTiltVergence();
  ASSERT_EQ(tree.num_variables(), 3);  // the mimic has no variable of its own
  EXPECT_EQ(tree.variable_name(2), "vergence");
  EXPECT_EQ(tree.FindVariable("right_vergence"), -1);
  const Eigen::Vector3d q(0.3, -0.2, 0.1);
  std::vector<Pose> X_WL;
  const Pose X_WR = Offset(1, 2, 3);
  tree.ForwardKinematics(q, X_WR, &X_WL);
  const Eigen::Matrix3d R_pan = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Matrix3d R_tilt = Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()).matrix();
  const Eigen::Vector3d p_head = Eigen::Vector3d(1, 2, 3.1);
  const Eigen::Vector3d p_right = p_head + R_pan * R_tilt * Eigen::Vector3d(0, -0.06, 0);
  const Eigen::Matrix3d R_right =
      R_pan * R_tilt * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).matrix();  // -1 * -z
  const int right = tree.FindLink("right_eye");
  EXPECT_LE((X_WL[right].translation() - p_right).norm(), kExactTolerance);
  EXPECT_LE((X_WL[right].linear() - R_right).norm(), kExactTolerance);
  EXPECT_DOUBLE_EQ(tree.JointValue(tree.FindJoint("right_vergence"), q), -0.1);
}

TEST(KinematicTree, JacobianMatchesCentralDifferencesOfForwardKinematics) {
  const KinematicTree tree = PanTiltVergence();
  const Eigen::Vector3d q(0.4, 0.3, -0.25);
  const Eigen::Vector3d p_L(0.2, 0.01, -0.03);  // a point ahead of the right eye
  const int link = tree.FindLink("right_eye");
  std::vector<Pose> X_WL;
  tree.ForwardKinematics(q, Pose::Identity(), &X_WL);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J;
  tree.Jacobian(X_WL, link, X_WL[link] * p_L, &J);
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d plus = q, minus = q;
    plus[i] += h;
    minus[i] -= h;
    std::vector<Pose> X_plus, X_minus;
    tree.ForwardKinematics(plus, Pose::Identity(), &X_plus);
    tree.ForwardKinematics(minus, Pose::Identity(), &X_minus);
    const Eigen::Vector3d v = (X_plus[link] * p_L - X_minus[link] * p_L) / (2 * h);
    // The angular velocity from the rotation's derivative: skew(w) = dR/dq * R^T.
    const Eigen::Matrix3d W = (X_plus[link].linear() - X_minus[link].linear()) / (2 * h) *
                              X_WL[link].linear().transpose();
    const Eigen::Vector3d w(W(2, 1), W(0, 2), W(1, 0));
    EXPECT_LE((J.col(i).tail<3>() - v).norm(), kFiniteDifferenceTolerance) << "variable " << i;
    EXPECT_LE((J.col(i).head<3>() - w).norm(), kFiniteDifferenceTolerance) << "variable " << i;
  }
  EXPECT_TRUE(tree.Moves(tree.FindJoint("right_vergence"), link));
  EXPECT_FALSE(tree.Moves(tree.FindJoint("vergence"), link));
}

// Each bad tree of issue 42 item 6: the message names the source, the element and what was
// expected.
struct BadTree {
  std::string name;
  std::function<void(std::vector<std::string>*, std::vector<JointSpec>*)> spoil;
  std::string element;
  std::string expected;
};

class BadTrees : public ::testing::TestWithParam<BadTree> {};

TEST_P(BadTrees, AreRefusedNamingTheElementAndWhatWasExpected) {
  std::vector<std::string> links = {"base", "neck", "head"};
  std::vector<JointSpec> joints = {
      Revolute("pan", "base", "neck", Pose::Identity(), Eigen::Vector3d::UnitZ()),
      Revolute("tilt", "neck", "head", Offset(0, 0, 0.1), Eigen::Vector3d::UnitY())};
  joints[1].line = 17;
  GetParam().spoil(&links, &joints);
  try {
    KinematicTree::Build(links, joints, "robots/bad.urdf");
    FAIL() << "expected an error";
  } catch (const FileError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("robots/bad.urdf"), HasSubstr(GetParam().element),
                                HasSubstr(GetParam().expected)));
  }
}

const double kNan = std::nan("");

INSTANTIATE_TEST_SUITE_P(
    Item6, BadTrees,
    ::testing::Values(
        BadTree{"Cycle",
                [](auto* links, auto* joints) {
                  links->push_back("a");
                  links->push_back("b");
                  joints->push_back(
                      Revolute("ab", "a", "b", Pose::Identity(), Eigen::Vector3d::UnitZ()));
                  joints->push_back(
                      Revolute("ba", "b", "a", Pose::Identity(), Eigen::Vector3d::UnitZ()));
                },
                "link a", "cycle"},
        BadTree{"MissingLink", [](auto*, auto* joints) { (*joints)[1].child = "skull"; },
                "robots/bad.urdf:17: joint tilt", "child link \"skull\" does not exist"},
        BadTree{"MissingMimicJoint",
                [](auto*, auto* joints) {
                  (*joints)[1].mimic = MimicSpec{"roll", 1, 0};
                },
                "joint tilt", "names joint \"roll\", which does not exist"},
        BadTree{"ZeroAxis", [](auto*, auto* joints) { (*joints)[1].axis.setZero(); }, "joint tilt",
                "must not be zero"},
        BadTree{"NanAxis", [](auto*, auto* joints) { (*joints)[1].axis.x() = kNan; }, "joint tilt",
                "<axis> must be finite"},
        BadTree{"LowerAboveUpper",
                [](auto*, auto* joints) {
                  (*joints)[1].lower = 1.0;
                  (*joints)[1].upper = -1.0;
                },
                "joint tilt", "expected lower <= upper"},
        BadTree{"NanLimit", [](auto*, auto* joints) { (*joints)[1].upper = kNan; }, "joint tilt",
                "lower and upper must be finite"},
        BadTree{"TwoParents",
                [](auto*, auto* joints) {
                  joints->push_back(Revolute("again", "base", "head", Pose::Identity(),
                                             Eigen::Vector3d::UnitZ()));
                },
                "joint again", "already has a parent joint, \"tilt\""},
        BadTree{"TwoRoots", [](auto* links, auto*) { links->push_back("stray"); }, "robot",
                "2 root links (\"base\", \"stray\")"},
        BadTree{"DuplicateJoint", [](auto*, auto* joints) { (*joints)[1].name = "pan"; },
                "joint pan", "used twice"},
        BadTree{"MimicCycle",
                [](auto*, auto* joints) {
                  (*joints)[0].mimic = MimicSpec{"tilt", 1, 0};
                  (*joints)[1].mimic = MimicSpec{"pan", 1, 0};
                },
                "joint", "form a cycle"}),
    [](const ::testing::TestParamInfo<BadTree>& info) { return info.param.name; });

TEST(KinematicTree, AContinuousJointHasNoLimitsAndAFixedJointNoVariable) {
  std::vector<JointSpec> joints = {
      Revolute("spin", "base", "wheel", Pose::Identity(), Eigen::Vector3d::UnitZ()),
      Revolute("mount", "wheel", "camera", Offset(0.1, 0, 0), Eigen::Vector3d::UnitZ())};
  joints[0].type = JointType::kContinuous;
  joints[0].lower = joints[0].upper = kNan;  // ignored, as URDF ignores them
  joints[1].type = JointType::kFixed;
  const KinematicTree tree = KinematicTree::Build({"base", "wheel", "camera"}, joints, "test");
  EXPECT_EQ(tree.num_variables(), 1);
  EXPECT_TRUE(std::isinf(tree.joint(0).lower));
  EXPECT_FALSE(tree.joint(1).moves());
}

}  // namespace
}  // namespace saccade::head
