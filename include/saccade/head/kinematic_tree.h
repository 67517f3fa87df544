#pragma once
// The kinematic tree of any robot head: links joined by revolute, continuous, prismatic, fixed
// and mimic joints, as URDF describes them (issue 42). Immutable once built; joint values live
// apart in a vector q (description vs state).
//
// Conventions (URDF's, http://wiki.ros.org/urdf/XML/joint). A joint J joins a parent link P
// to a child link C. Its origin X_PJ places the joint frame in P; the child frame is the joint
// frame moved by the joint's value v along or about the unit axis a (given in the joint frame):
//   revolute, continuous:  X_PC = X_PJ * Rot(a, v)          v in rad
//   prismatic:             X_PC = X_PJ * Trans(a * v)       v in m
//   fixed:                 X_PC = X_PJ
// A mimic joint has no value of its own: v = multiplier * v_source + offset (URDF's <mimic>;
// how a URDF couples two eyes to one vergence motor). Chains of mimics resolve to the first
// joint that is not one.
//
// The variables q are the actuated joints: every revolute, continuous or prismatic joint that
// is not a mimic, in the order the joints were given. The tree's world pose is X_WR, the root
// link's frame in the world.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "saccade/geometry/pose.h"

namespace saccade::head {

enum class JointType { kRevolute, kContinuous, kPrismatic, kFixed };
/// "revolute", "continuous", "prismatic", "fixed" (URDF's names).
const char* ToString(JointType type);

/// URDF's <mimic>: this joint's value = multiplier * (the named joint's value) + offset.
struct MimicSpec {
  std::string joint;
  double multiplier = 1.0;
  double offset = 0.0;
};

/// One joint as a description gives it, before validation.
struct JointSpec {
  std::string name;
  JointType type = JointType::kFixed;
  std::string parent;                                ///< parent link's name
  std::string child;                                 ///< child link's name
  geometry::Pose X_PJ = geometry::Pose::Identity();  ///< joint frame in the parent link
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();   ///< in the joint frame; any length > 0
  double lower = 0.0;                                ///< rad or m (continuous: ignored)
  double upper = 0.0;                                ///< rad or m (continuous: ignored)
  double max_velocity = 0.0;                         ///< rad/s or m/s; 0 when not given
  std::optional<MimicSpec> mimic;
  int line = 0;  ///< the element's line in `source`, for errors (0: unknown)
};

/// A validated tree. Cheap to copy (a few vectors); share it by const reference.
class KinematicTree {
 public:
  /// One joint after validation: indices instead of names, a unit axis, and for an actuated
  /// joint its variable, for a mimic the variable it follows.
  struct Joint {
    std::string name;
    JointType type = JointType::kFixed;
    int parent = -1;  ///< link index
    int child = -1;   ///< link index
    geometry::Pose X_PJ = geometry::Pose::Identity();
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  ///< unit length
    double lower = 0.0;                               ///< -inf for continuous joints
    double upper = 0.0;                               ///< +inf for continuous joints
    double max_velocity = 0.0;
    /// The variable this joint moves with (its own, or its mimic source's); -1 when fixed.
    int variable = -1;
    double multiplier = 1.0;  ///< value = multiplier * q[variable] + offset
    double offset = 0.0;
    bool is_mimic = false;
    bool moves() const { return variable >= 0; }
  };

  /// Validates and builds. Throws saccade::FileError(source, line, "joint NAME" or "link NAME",
  /// what) when: a name is empty or used twice; a joint names a parent or child link that does
  /// not exist; a link has two parent joints; there is not exactly one root link; a link is
  /// not reachable from the root (a cycle); an axis is zero or not finite; an origin is not
  /// finite; limits are not finite or lower > upper (revolute, prismatic); a velocity limit is
  /// negative or not finite; a mimic names a joint that does not exist, is fixed, or forms a
  /// cycle of mimics, or its multiplier or offset is not finite. `link_lines` (optional, same
  /// order as `links`) give the links' lines for the messages.
  static KinematicTree Build(const std::vector<std::string>& links,
                             const std::vector<JointSpec>& joints, const std::string& source,
                             const std::vector<int>& link_lines = {});

  int num_links() const { return static_cast<int>(links_.size()); }
  int num_joints() const { return static_cast<int>(joints_.size()); }
  /// The number of variables q (actuated joints).
  int num_variables() const { return static_cast<int>(variables_.size()); }

  const std::string& link_name(int link) const { return links_[link]; }
  /// The link's index, or -1 when there is none of that name.
  int FindLink(const std::string& name) const;
  /// The joint whose child is `link`; -1 for the root.
  int parent_joint(int link) const { return parent_joint_[link]; }
  int root() const { return root_; }

  const Joint& joint(int index) const { return joints_[index]; }
  /// The joint's index, or -1 when there is none of that name.
  int FindJoint(const std::string& name) const;
  /// Joints parents-first: a joint's parent link is placed before it moves its child.
  const std::vector<int>& joint_order() const { return order_; }

  /// The joint index of variable i.
  int variable_joint(int variable) const { return variables_[variable]; }
  const std::string& variable_name(int variable) const {
    return joints_[variables_[variable]].name;
  }
  /// The variable of the named actuated joint, or -1 (unknown, fixed, or a mimic).
  int FindVariable(const std::string& name) const;

  /// A joint's value for the variables q (its own, or its mimic source's times the multiplier
  /// plus the offset); 0 for a fixed joint.
  double JointValue(int joint, const Eigen::Ref<const Eigen::VectorXd>& q) const;

  /// Forward kinematics: X_WL of every link (indexed as the links), for variables q (size
  /// num_variables()) and the root's pose X_WR. Does not check limits; never throws; allocates
  /// only when X_WL has the wrong size. One pass over joint_order().
  void ForwardKinematics(const Eigen::Ref<const Eigen::VectorXd>& q, const geometry::Pose& X_WR,
                         std::vector<geometry::Pose>* X_WL) const;

  /// The spatial Jacobian of a point fixed to `link`, at the poses X_WL from
  /// ForwardKinematics: a 6 x num_variables() matrix whose column i is the velocity of the
  /// point when q_i moves at unit speed, in world axes: rows 0-2 the link's angular velocity
  /// (rad/s), rows 3-5 the point's linear velocity (m/s). p_W is the point in the world. Mimic
  /// joints add multiplier times their column to their source's.
  void Jacobian(const std::vector<geometry::Pose>& X_WL, int link, const Eigen::Vector3d& p_W,
                Eigen::Matrix<double, 6, Eigen::Dynamic>* J) const;

  /// Whether a joint moves `link` (lies on the path from the root to it).
  bool Moves(int joint, int link) const;

 private:
  KinematicTree() = default;
  // Build's steps (kinematic_tree.cc).
  void OrderFromTheRoot(const std::string& source, const std::vector<int>& link_lines);
  void AssignVariables(const std::vector<JointSpec>& joints, const std::string& source);

  std::vector<std::string> links_;
  std::vector<int> parent_joint_;
  std::vector<Joint> joints_;
  std::vector<int> order_;
  std::vector<int> variables_;
  int root_ = 0;
};

}  // namespace saccade::head
