// saccade's kinematics of any tree against Orocos KDL (issue 42): forward kinematics of every
// link and the Jacobians of every link's origin, on 1,000 random configurations of every URDF
// the project ships (robots/) and of a test robot with every joint type. KDL's tree is built
// from urdfdom's model the way ROS's kdl_parser builds it, independently of saccade's tree.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <filesystem>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl/treefksolverpos_recursive.hpp>
#include <kdl/treejnttojacsolver.hpp>
#include <map>
#include <random>
#include <set>

#include "saccade/head/urdf.h"

namespace saccade::head {
namespace {

namespace fs = std::filesystem;
using geometry::Pose;

// The bound. Both sides compose a handful of 4x4 products of numbers below 10: their
// rounding differs by a few ulps of 1 (1e-16), far below it.
constexpr double kKdlTolerance = 1e-12;
constexpr int kConfigurations = 1000;

KDL::Frame ToKdl(const urdf::Pose& pose) {
  return KDL::Frame(
      KDL::Rotation::Quaternion(pose.rotation.x, pose.rotation.y, pose.rotation.z, pose.rotation.w),
      KDL::Vector(pose.position.x, pose.position.y, pose.position.z));
}

// kdl_parser's treeFromUrdfModel, without inertias: one segment per child link, its joint
// turning about the axis expressed in the parent, at the joint's origin.
void AddChildren(const urdf::LinkConstSharedPtr& link, KDL::Tree* tree) {
  for (const urdf::LinkSharedPtr& child : link->child_links) {
    const urdf::Joint& j = *child->parent_joint;
    const KDL::Frame F = ToKdl(j.parent_to_joint_origin_transform);
    const KDL::Vector axis = F.M * KDL::Vector(j.axis.x, j.axis.y, j.axis.z);
    KDL::Joint joint(j.name, KDL::Joint::None);
    if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS) {
      joint = KDL::Joint(j.name, F.p, axis, KDL::Joint::RotAxis);
    } else if (j.type == urdf::Joint::PRISMATIC) {
      joint = KDL::Joint(j.name, F.p, axis, KDL::Joint::TransAxis);
    }
    ASSERT_TRUE(tree->addSegment(KDL::Segment(child->name, joint, F), link->name));
    AddChildren(child, tree);
  }
}

struct Reference {
  urdf::ModelInterfaceSharedPtr model;
  KDL::Tree tree;
  std::map<std::string, int> q_nr;  // joint name -> KDL's joint index
};

Reference MakeReference(const fs::path& path) {
  Reference r;
  r.model = urdf::parseURDFFile(path.string());
  EXPECT_TRUE(r.model) << path;
  r.tree = KDL::Tree(r.model->getRoot()->name);
  AddChildren(r.model->getRoot(), &r.tree);
  for (const auto& [name, element] : r.tree.getSegments()) {
    const KDL::Joint& joint = GetTreeElementSegment(element).getJoint();
    if (joint.getType() != KDL::Joint::None) r.q_nr[joint.getName()] = GetTreeElementQNr(element);
  }
  return r;
}

// The value of a URDF joint for saccade's variables: from urdfdom's <mimic>, independently.
double UrdfJointValue(const urdf::ModelInterface& model, const KinematicTree& tree,
                      const std::string& name, const Eigen::VectorXd& q) {
  const urdf::JointConstSharedPtr joint = model.getJoint(name);
  if (joint->mimic) {
    return joint->mimic->multiplier * UrdfJointValue(model, tree, joint->mimic->joint_name, q) +
           joint->mimic->offset;
  }
  return q[tree.FindVariable(name)];
}

Eigen::VectorXd RandomConfiguration(const KinematicTree& tree, std::mt19937_64* random) {
  Eigen::VectorXd q(tree.num_variables());
  for (int i = 0; i < q.size(); ++i) {
    const KinematicTree::Joint& joint = tree.joint(tree.variable_joint(i));
    const double lower = std::isfinite(joint.lower) ? joint.lower : -2 * M_PI;
    const double upper = std::isfinite(joint.upper) ? joint.upper : 2 * M_PI;
    q[i] = std::uniform_real_distribution<double>(lower, upper)(*random);
  }
  return q;
}

std::vector<fs::path> Robots() {
  std::vector<fs::path> paths = {fs::path(SACCADE_SOURCE_DIR) / "tests/head/data/every_joint.urdf"};
  for (const auto& entry :
       fs::recursive_directory_iterator(fs::path(SACCADE_SOURCE_DIR) / "robots")) {
    if (entry.path().extension() == ".urdf") paths.push_back(entry.path());
  }
  std::sort(paths.begin() + 1, paths.end());
  return paths;
}

class KdlAgreement : public ::testing::TestWithParam<fs::path> {};

TEST_P(KdlAgreement, ForwardKinematicsAndJacobiansOfEveryLinkAgreeWithKdl) {
  UrdfOptions options;
  options.visuals_optional = true;  // the kinematics do not need the meshes
  const UrdfModel robot = LoadUrdfFile(GetParam(), options);
  const KinematicTree& tree = robot.tree;
  const Reference reference = MakeReference(GetParam());
  ASSERT_EQ(reference.tree.getNrOfJoints(), static_cast<unsigned>(reference.q_nr.size()));
  KDL::TreeFkSolverPos_recursive fk(reference.tree);
  KDL::TreeJntToJacSolver jacobian_solver(reference.tree);

  std::mt19937_64 random(42);
  std::vector<Pose> X_WL;
  Eigen::Matrix<double, 6, Eigen::Dynamic> J;
  double worst_pose = 0.0;
  double worst_jacobian = 0.0;
  for (int n = 0; n < kConfigurations; ++n) {
    const Eigen::VectorXd q = RandomConfiguration(tree, &random);
    KDL::JntArray q_kdl(reference.tree.getNrOfJoints());
    for (const auto& [name, index] : reference.q_nr) {
      q_kdl(index) = UrdfJointValue(*reference.model, tree, name, q);
    }
    tree.ForwardKinematics(q, Pose::Identity(), &X_WL);
    for (int link = 0; link < tree.num_links(); ++link) {
      KDL::Frame frame;
      ASSERT_GE(fk.JntToCart(q_kdl, frame, tree.link_name(link)), 0) << tree.link_name(link);
      for (int r = 0; r < 3; ++r) {
        worst_pose = std::max(worst_pose, std::abs(X_WL[link].translation()[r] - frame.p(r)));
        for (int c = 0; c < 3; ++c) {
          worst_pose = std::max(worst_pose, std::abs(X_WL[link].linear()(r, c) - frame.M(r, c)));
        }
      }
      // KDL: a column per KDL joint, (linear; angular) of the link's origin. saccade: a column
      // per variable, (angular; linear), mimic joints folded into their source.
      KDL::Jacobian J_kdl(reference.tree.getNrOfJoints());
      ASSERT_GE(jacobian_solver.JntToJac(q_kdl, J_kdl, tree.link_name(link)), 0);
      Eigen::Matrix<double, 6, Eigen::Dynamic> expected =
          Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, tree.num_variables());
      for (const auto& [name, index] : reference.q_nr) {
        const int j = tree.FindJoint(name);
        const KinematicTree::Joint& joint = tree.joint(j);
        // d(joint value)/d(its variable), from the reference's chain of <mimic>s.
        Eigen::VectorXd unit = Eigen::VectorXd::Zero(tree.num_variables());
        unit[joint.variable] = 1.0;
        const double slope = UrdfJointValue(*reference.model, tree, name, unit) -
                             UrdfJointValue(*reference.model, tree, name,
                                            Eigen::VectorXd::Zero(tree.num_variables()));
        expected.col(joint.variable).head<3>() += slope * J_kdl.data.col(index).tail<3>();
        expected.col(joint.variable).tail<3>() += slope * J_kdl.data.col(index).head<3>();
      }
      tree.Jacobian(X_WL, link, X_WL[link].translation(), &J);
      worst_jacobian = std::max(worst_jacobian, (J - expected).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LE(worst_pose, kKdlTolerance) << GetParam();
  EXPECT_LE(worst_jacobian, kKdlTolerance) << GetParam();
  RecordProperty("worst_pose", fmt::format("{:.3g}", worst_pose));
  RecordProperty("worst_jacobian", fmt::format("{:.3g}", worst_jacobian));
}

INSTANTIATE_TEST_SUITE_P(EveryShippedHead, KdlAgreement, ::testing::ValuesIn(Robots()),
                         [](const ::testing::TestParamInfo<fs::path>& info) {
                           return info.param.stem().string();
                         });

TEST(KdlAgreement, TheTestRobotHasEveryJointType) {
  const UrdfModel robot =
      LoadUrdfFile(fs::path(SACCADE_SOURCE_DIR) / "tests/head/data/every_joint.urdf");
  std::set<JointType> types;
  int mimics = 0;
  for (int j = 0; j < robot.tree.num_joints(); ++j) {
    types.insert(robot.tree.joint(j).type);
    mimics += robot.tree.joint(j).is_mimic;
  }
  EXPECT_EQ(types.size(), 4u);
  EXPECT_EQ(mimics, 2);
  EXPECT_EQ(robot.tree.num_variables(), 5);
}

}  // namespace
}  // namespace saccade::head
