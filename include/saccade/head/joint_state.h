#pragma once
// A head's joint values by name (issue 42): positions (rad, or m for a prismatic joint),
// velocities or targets of its actuated joints, in the head's order (HeadModel::joint_names(),
// the URDF's order). The names are shared, not copied: a JointState is a vector and a pointer.
// POPEYE's joints are named pan, tilt, left and right (head_description.h gives their signs),
// so its JSON form, {"left": .., "pan": .., "right": .., "tilt": ..}, is what it always was.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace saccade::head {

/// The names of a head's actuated joints, in its order.
using JointNames = std::vector<std::string>;

class JointState {
 public:
  /// No joints.
  JointState() = default;
  /// Every joint of `names` at 0.
  explicit JointState(std::shared_ptr<const JointNames> names);
  /// The values in the names' order. Throws InvalidArgument when the sizes differ.
  JointState(std::shared_ptr<const JointNames> names, Eigen::VectorXd values);
  /// POPEYE's four joints, for its legacy code (appendix A) and tests.
  static JointState Popeye(double pan, double tilt, double left, double right);
  /// "pan", "tilt", "left", "right".
  static const std::shared_ptr<const JointNames>& PopeyeNames();

  int size() const { return static_cast<int>(values_.size()); }
  bool empty() const { return values_.size() == 0; }
  const JointNames& names() const;
  const std::shared_ptr<const JointNames>& shared_names() const { return names_; }
  const std::string& name(int joint) const { return names()[joint]; }
  /// The joint's index, or -1 when there is none of that name.
  int Find(const std::string& name) const;

  double& operator[](int joint) { return values_[joint]; }
  double operator[](int joint) const { return values_[joint]; }
  /// By name; throws InvalidArgument naming the joint and listing the names there are.
  double& at(const std::string& name);
  double at(const std::string& name) const;

  const Eigen::VectorXd& values() const { return values_; }
  Eigen::VectorXd& values() { return values_; }

  /// The same joints, other values (same size, else InvalidArgument).
  JointState With(Eigen::VectorXd values) const { return JointState(names_, std::move(values)); }
  /// The values of this state's joints in the order of `names`. Throws InvalidArgument naming
  /// the joints that one side has and the other has not (a JSON command that names a joint
  /// the head does not have, or leaves one out).
  JointState ArrangedAs(const std::shared_ptr<const JointNames>& names) const;

  /// Same names in the same order and equal values.
  bool operator==(const JointState& other) const;

 private:
  std::shared_ptr<const JointNames> names_;
  Eigen::VectorXd values_;
};

/// "pan, tilt, left, right": the names for messages.
std::string ListNames(const JointNames& names);

}  // namespace saccade::head
