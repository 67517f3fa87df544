#include "saccade/head/kinematic_tree.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>

#include "saccade/core/error.h"

namespace saccade::head {
namespace {

using geometry::Pose;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The finite-number checks of Build, with the joint named in the error.
class TreeChecker {
 public:
  TreeChecker(const std::string& source, const std::vector<JointSpec>& joints)
      : source_(source), joints_(joints) {}

  [[noreturn]] void Fail(int joint, const std::string& what) const {
    throw FileError(source_, joints_[joint].line, fmt::format("joint {}", joints_[joint].name),
                    what);
  }

  void CheckGeometry(int j) const {
    const JointSpec& s = joints_[j];
    if (!s.X_PJ.matrix().allFinite()) {
      Fail(j, "the <origin> must be finite (xyz in metres, rpy in radians)");
    }
    if (s.type == JointType::kFixed) return;
    if (!s.axis.allFinite()) {
      Fail(j, fmt::format("the <axis> must be finite, got ({}, {}, {})", s.axis.x(), s.axis.y(),
                          s.axis.z()));
    }
    if (s.axis.norm() < 1e-12) {
      Fail(j, fmt::format("the <axis> must not be zero, got ({}, {}, {}); expected a direction "
                          "such as \"0 0 1\"",
                          s.axis.x(), s.axis.y(), s.axis.z()));
    }
  }

  void CheckLimits(int j) const {
    const JointSpec& s = joints_[j];
    if (s.type == JointType::kRevolute || s.type == JointType::kPrismatic) {
      if (!std::isfinite(s.lower) || !std::isfinite(s.upper)) {
        Fail(j, fmt::format("the <limit> lower and upper must be finite, got [{}, {}]", s.lower,
                            s.upper));
      }
      if (s.lower > s.upper) {
        Fail(j, fmt::format("the <limit> lower ({}) is above upper ({}); expected lower <= upper",
                            s.lower, s.upper));
      }
    }
    if (!std::isfinite(s.max_velocity) || s.max_velocity < 0.0) {
      Fail(j, fmt::format("the <limit> velocity must be finite and >= 0, got {}", s.max_velocity));
    }
    if (s.mimic && (!std::isfinite(s.mimic->multiplier) || !std::isfinite(s.mimic->offset))) {
      Fail(j, fmt::format("the <mimic> multiplier and offset must be finite, got {} and {}",
                          s.mimic->multiplier, s.mimic->offset));
    }
  }

 private:
  const std::string& source_;
  const std::vector<JointSpec>& joints_;
};

Pose JointMotion(const KinematicTree::Joint& joint, double value) {
  Pose X = Pose::Identity();
  switch (joint.type) {
    case JointType::kRevolute:
    case JointType::kContinuous:
      X.linear() = Eigen::AngleAxisd(value, joint.axis).toRotationMatrix();
      break;
    case JointType::kPrismatic:
      X.translation() = joint.axis * value;
      break;
    case JointType::kFixed:
      break;
  }
  return X;
}

}  // namespace

const char* ToString(JointType type) {
  switch (type) {
    case JointType::kRevolute:
      return "revolute";
    case JointType::kContinuous:
      return "continuous";
    case JointType::kPrismatic:
      return "prismatic";
    case JointType::kFixed:
      return "fixed";
  }
  return "?";
}

KinematicTree KinematicTree::Build(const std::vector<std::string>& links,
                                   const std::vector<JointSpec>& joints, const std::string& source,
                                   const std::vector<int>& link_lines) {
  const auto link_line = [&](int link) {
    return link < static_cast<int>(link_lines.size()) ? link_lines[link] : 0;
  };
  const TreeChecker check(source, joints);
  KinematicTree tree;
  tree.links_ = links;
  std::map<std::string, int> link_index;
  for (int l = 0; l < static_cast<int>(links.size()); ++l) {
    if (links[l].empty()) throw FileError(source, link_line(l), "link", "a link has no name");
    if (!link_index.emplace(links[l], l).second) {
      throw FileError(source, link_line(l), fmt::format("link {}", links[l]),
                      "the link name is used twice; expected unique names");
    }
  }
  if (links.empty()) throw FileError(source, 0, "robot", "the robot has no <link>");

  std::map<std::string, int> joint_index;
  tree.parent_joint_.assign(links.size(), -1);
  for (int j = 0; j < static_cast<int>(joints.size()); ++j) {
    const JointSpec& s = joints[j];
    if (s.name.empty()) throw FileError(source, s.line, "joint", "a joint has no name");
    if (!joint_index.emplace(s.name, j).second) {
      check.Fail(j, "the joint name is used twice; expected unique names");
    }
    Joint joint;
    joint.name = s.name;
    joint.type = s.type;
    for (const auto& [role, name, index] :
         {std::tuple{"parent", &s.parent, &joint.parent}, {"child", &s.child, &joint.child}}) {
      const auto it = link_index.find(*name);
      if (it == link_index.end()) {
        check.Fail(j, fmt::format("its {} link \"{}\" does not exist", role, *name));
      }
      *index = it->second;
    }
    if (joint.parent == joint.child) check.Fail(j, "its parent and child are the same link");
    if (tree.parent_joint_[joint.child] >= 0) {
      check.Fail(j, fmt::format("link \"{}\" already has a parent joint, \"{}\"; a link has one",
                                s.child, joints[tree.parent_joint_[joint.child]].name));
    }
    tree.parent_joint_[joint.child] = j;
    check.CheckGeometry(j);
    check.CheckLimits(j);
    joint.X_PJ = s.X_PJ;
    if (s.type != JointType::kFixed) joint.axis = s.axis.normalized();
    joint.lower = s.type == JointType::kContinuous ? -kInfinity : s.lower;
    joint.upper = s.type == JointType::kContinuous ? kInfinity : s.upper;
    if (s.type == JointType::kFixed) joint.lower = joint.upper = 0.0;
    joint.max_velocity = s.max_velocity;
    tree.joints_.push_back(joint);
  }

  tree.OrderFromTheRoot(source, link_lines);
  tree.AssignVariables(joints, source);
  return tree;
}

// Exactly one root, every link reachable from it, and the joints parents first.
void KinematicTree::OrderFromTheRoot(const std::string& source,
                                     const std::vector<int>& link_lines) {
  KinematicTree& tree = *this;
  const std::vector<std::string>& links = links_;
  const auto link_line = [&](int link) {
    return link < static_cast<int>(link_lines.size()) ? link_lines[link] : 0;
  };
  // Exactly one root, and every link reachable from it (a cycle leaves its links unreached:
  // each has a parent, so they are not roots).
  std::vector<int> roots;
  for (int l = 0; l < tree.num_links(); ++l) {
    if (tree.parent_joint_[l] < 0) roots.push_back(l);
  }
  if (roots.size() != 1) {
    std::string names;
    for (int r : roots) names += fmt::format("{}\"{}\"", names.empty() ? "" : ", ", links[r]);
    throw FileError(source, 0, "robot",
                    roots.empty() ? "no root link: every link has a parent joint (a cycle)"
                                  : fmt::format("{} root links ({}); expected exactly one link "
                                                "without a parent joint",
                                                roots.size(), names));
  }
  tree.root_ = roots[0];
  std::vector<int> frontier = {tree.root_};
  std::vector<bool> reached(links.size(), false);
  reached[tree.root_] = true;
  while (!frontier.empty()) {
    const int link = frontier.back();
    frontier.pop_back();
    for (int j = 0; j < tree.num_joints(); ++j) {
      if (tree.joints_[j].parent != link) continue;
      tree.order_.push_back(j);
      reached[tree.joints_[j].child] = true;
      frontier.push_back(tree.joints_[j].child);
    }
  }
  for (int l = 0; l < tree.num_links(); ++l) {
    if (!reached[l]) {
      throw FileError(source, link_line(l), fmt::format("link {}", links[l]),
                      fmt::format("not reachable from the root link \"{}\": its parent joints "
                                  "form a cycle; expected a tree",
                                  links[tree.root_]));
    }
  }
  // Parents first, then by the order given (deterministic).
  std::vector<int> depth(links.size(), 0);
  for (int j : tree.order_) depth[tree.joints_[j].child] = depth[tree.joints_[j].parent] + 1;
  std::stable_sort(tree.order_.begin(), tree.order_.end(), [&](int a, int b) {
    return depth[tree.joints_[a].child] < depth[tree.joints_[b].child];
  });
}

// The actuated joints' variables, then each mimic resolved to the variable it follows.
void KinematicTree::AssignVariables(const std::vector<JointSpec>& joints,
                                    const std::string& source) {
  KinematicTree& tree = *this;
  const TreeChecker check(source, joints);
  std::map<std::string, int> joint_index;
  for (int j = 0; j < static_cast<int>(joints.size()); ++j) joint_index.emplace(joints[j].name, j);
  // Variables, then mimics resolved to them.
  for (int j = 0; j < tree.num_joints(); ++j) {
    Joint& joint = tree.joints_[j];
    if (joint.type == JointType::kFixed || joints[j].mimic) continue;
    joint.variable = tree.num_variables();
    tree.variables_.push_back(j);
  }
  for (int j = 0; j < tree.num_joints(); ++j) {
    if (!joints[j].mimic) continue;
    Joint& joint = tree.joints_[j];
    if (joint.type == JointType::kFixed) check.Fail(j, "a fixed joint cannot mimic another");
    joint.is_mimic = true;
    double multiplier = 1.0;
    double offset = 0.0;
    int current = j;
    for (int steps = 0; joints[current].mimic; ++steps) {
      const MimicSpec& m = *joints[current].mimic;
      const auto it = joint_index.find(m.joint);
      if (it == joint_index.end()) {
        check.Fail(current,
                   fmt::format("its <mimic> names joint \"{}\", which does not exist", m.joint));
      }
      if (joints[it->second].type == JointType::kFixed) {
        check.Fail(current,
                   fmt::format("its <mimic> names joint \"{}\", which is fixed; expected a "
                               "revolute, continuous or prismatic joint",
                               m.joint));
      }
      if (steps > tree.num_joints()) check.Fail(j, "its <mimic> joints form a cycle");
      offset = multiplier * m.offset + offset;
      multiplier *= m.multiplier;
      current = it->second;
    }
    joint.variable = tree.joints_[current].variable;
    joint.multiplier = multiplier;
    joint.offset = offset;
  }
}

int KinematicTree::FindLink(const std::string& name) const {
  for (int l = 0; l < num_links(); ++l) {
    if (links_[l] == name) return l;
  }
  return -1;
}

int KinematicTree::FindJoint(const std::string& name) const {
  for (int j = 0; j < num_joints(); ++j) {
    if (joints_[j].name == name) return j;
  }
  return -1;
}

int KinematicTree::FindVariable(const std::string& name) const {
  const int j = FindJoint(name);
  return j >= 0 && !joints_[j].is_mimic ? joints_[j].variable : -1;
}

double KinematicTree::JointValue(int joint, const Eigen::Ref<const Eigen::VectorXd>& q) const {
  const Joint& J = joints_[joint];
  if (!J.moves()) return 0.0;
  if (!J.is_mimic) return q[J.variable];
  return J.multiplier * q[J.variable] + J.offset;
}

void KinematicTree::ForwardKinematics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                      const geometry::Pose& X_WR,
                                      std::vector<geometry::Pose>* X_WL) const {
  SACCADE_ASSERT(q.size() == num_variables(), "ForwardKinematics: q has the wrong size");
  if (static_cast<int>(X_WL->size()) != num_links()) X_WL->resize(links_.size());
  (*X_WL)[root_] = X_WR;
  for (int j : order_) {
    const Joint& joint = joints_[j];
    (*X_WL)[joint.child] =
        (*X_WL)[joint.parent] * joint.X_PJ * JointMotion(joint, JointValue(j, q));
  }
}

bool KinematicTree::Moves(int joint, int link) const {
  for (int j = parent_joint_[link]; j >= 0; j = parent_joint_[joints_[j].parent]) {
    if (j == joint) return true;
  }
  return false;
}

void KinematicTree::Jacobian(const std::vector<geometry::Pose>& X_WL, int link,
                             const Eigen::Vector3d& p_W,
                             Eigen::Matrix<double, 6, Eigen::Dynamic>* J) const {
  J->setZero(6, num_variables());
  // A joint's motion leaves its axis fixed, so the axis and origin in the world follow from
  // the child's pose: a_W = R_WC * a, through the child's origin (the joint's origin).
  for (int j = parent_joint_[link]; j >= 0; j = parent_joint_[joints_[j].parent]) {
    const Joint& joint = joints_[j];
    if (!joint.moves()) continue;
    const Pose& X_WC = X_WL[joint.child];
    const Eigen::Vector3d a_W = X_WC.linear() * joint.axis;
    Eigen::Matrix<double, 6, 1> column;
    if (joint.type == JointType::kPrismatic) {
      column << Eigen::Vector3d::Zero(), a_W;
    } else {
      column << a_W, a_W.cross(p_W - X_WC.translation());
    }
    J->col(joint.variable) += joint.multiplier * column;
  }
}

}  // namespace saccade::head
