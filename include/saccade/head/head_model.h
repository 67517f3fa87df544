#pragma once
// Any stereo head (issue 42): its kinematic tree (from a URDF, or built from POPEYE's appendix-A
// geometry), its two eye cameras, which joints saccade drives and how, and the rule that picks
// one posture among those that fixate a point. Immutable once loaded; joint values live apart
// in a vector q over the tree's variables (KinematicTree: the actuated joints, URDF order).
//
// A head file (robots/<name>.yaml) either names a URDF (`urdf:`, documented in
// robots/humanoid.yaml and docs/formats.md) or is POPEYE's legacy format (`geometry:`,
// robots/popeye.yaml), whose tree is built here: base_link -pan(z)-> neck_link -tilt(y), D up->
// tilt_link -fixed, H up-> cyclopean_link -left(z), B left / right(z), B right-> *_eye_link
// -fixed, delta ahead, optical axes-> *_camera_optical. Joint names and signs are those of
// head_description.h.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/head_description.h"
#include "saccade/head/joint_state.h"
#include "saccade/head/kinematic_tree.h"
#include "saccade/head/urdf.h"

namespace saccade::head {

/// One of the two eye cameras.
struct EyeCamera {
  int link = 0;                                      ///< the tree link it is fixed to
  geometry::Pose X_LC = geometry::Pose::Identity();  ///< its optical frame (OpenCV) in the link
  /// (a placeholder until a head file sets it)
  geometry::CameraModel model{geometry::Intrinsics(640, 480, 500.0, 500.0, 319.5, 239.5)};
  /// The clip planes a Gazebo sensor gives (near, far in m); std::nullopt otherwise.
  std::optional<std::pair<double, double>> clip;
};

/// How saccade treats one actuated joint.
struct JointSettings {
  JointLimits limits;  ///< position (URDF's, narrowed by the head file), velocity, acceleration
  bool driven = true;  ///< false: held at `hold`, never commanded
  double hold = 0.0;   ///< rad or m, the value of a joint that is not driven
  std::optional<ServoMapping> servo;
};

/// Which posture fixation picks when several fixate (head file `fixation:`). Among the postures
/// that put both optical axes through the target, within the limits, the one that minimises
///   sum_i weights[i] * (q[i] - preferred[i])^2
/// over the joints that are driven and not held; held joints keep their value; a symmetric
/// pair (a, b, sign) is held at q[b] = sign * q[a] (POPEYE's appendix A: left = -right).
struct FixationRule {
  struct Pair {
    int a = 0;
    int b = 0;
    double sign = -1.0;
  };
  std::vector<bool> hold;     ///< per variable
  Eigen::VectorXd weights;    ///< per variable, > 0
  Eigen::VectorXd preferred;  ///< per variable
  std::vector<Pair> symmetric;
};

class HeadModel {
 public:
  /// Loads a head file of either format. Throws saccade::FileError naming the file, the line
  /// and the key (and the URDF's errors, urdf.h), for: unknown or missing keys, a joint name
  /// the URDF does not have or that is fixed or a mimic, limits that widen the URDF's, a
  /// driven joint without a velocity or acceleration limit, a camera link or Gazebo sensor that
  /// does not exist, a camera given both ways or neither, servo ids used twice, a fixation rule
  /// naming unknown joints or a weight <= 0.
  static HeadModel FromFile(const std::filesystem::path& path);
  /// Same from text; `source` names it in errors; relative paths are under `base_dir`.
  static HeadModel FromYamlString(const std::string& text, const std::string& source,
                                  const std::filesystem::path& base_dir);
  /// POPEYE's legacy description as a tree (see the file's header), with the appendix-A rule.
  static HeadModel FromDescription(const HeadDescription& legacy);

  const std::string& name() const { return name_; }
  const KinematicTree& tree() const { return tree_; }
  /// The tree's root link in the world.
  const geometry::Pose& X_WB() const { return X_WB_; }

  /// The number of actuated joints (the size of q).
  int num_joints() const { return tree_.num_variables(); }
  const std::string& joint_name(int joint) const { return tree_.variable_name(joint); }
  /// The actuated joints' names, shared by every JointState of this head.
  const std::shared_ptr<const JointNames>& joint_names() const { return joint_names_; }
  /// A JointState of this head's joints with these values (size num_joints()).
  JointState State(Eigen::VectorXd values) const {
    return JointState(joint_names_, std::move(values));
  }
  /// POPEYE's four joints as this head's (a legacy head's, whose joints are pan, tilt, left,
  /// right).
  JointState State(const PopeyeJoints& q) const {
    return State(Eigen::Vector4d(q.pan, q.tilt, q.left, q.right));
  }
  /// HomePosture() as a JointState.
  JointState Home() const { return State(HomePosture()); }
  /// `joints` in this head's order, by name (a state decoded from JSON has its keys' order).
  /// Throws InvalidArgument naming unknown and missing joints.
  JointState Arrange(const JointState& joints) const;
  /// The posture of `joints` in the head's order (size num_joints): the home posture when
  /// `joints` is empty. Throws InvalidArgument naming unknown or missing joints.
  Eigen::VectorXd Posture(const JointState& joints) const;
  /// The variable of that name; -1 when the head has no such actuated joint.
  int FindJoint(const std::string& name) const { return tree_.FindVariable(name); }
  const JointSettings& joint(int joint) const { return joints_[joint]; }
  const EyeCamera& camera(int eye) const { return cameras_[eye]; }  ///< 0 left, 1 right
  const FixationRule& fixation_rule() const { return rule_; }
  const std::vector<UrdfVisual>& visuals() const { return visuals_; }
  /// The URDF's text (ROS's robot_description); empty for a legacy head.
  const std::string& urdf_xml() const { return urdf_xml_; }
  /// The head file.
  const std::string& source() const { return source_; }
  /// POPEYE's appendix-A geometry when the head was loaded from the legacy format.
  const std::optional<HeadGeometry>& appendix_a() const { return appendix_a_; }

  /// The same head placed elsewhere in the world (a scene's `robot.pose`).
  HeadModel WithPose(const geometry::Pose& X_WB) const;
  /// The same head with another camera model for an eye (a scene's calibration file).
  HeadModel WithCamera(int eye, const geometry::CameraModel& model) const;

  /// For a legacy POPEYE head (appendix_a()), the same head as a HeadDescription, for appendix
  /// A's closed-form and Newton solvers (kinematics.h): its pose, limits, cameras and servos.
  /// std::nullopt for any other head.
  std::optional<HeadDescription> AppendixAHead() const;
  /// Both eye cameras' optical frames in the world at `joints` (empty: home).
  std::array<geometry::Pose, 2> CameraPoses(const JointState& joints) const;

  /// Driven joints at 0 (clamped into their limits), the others at their hold value.
  Eigen::VectorXd HomePosture() const;
  /// X_WL of every tree link for q.
  void ForwardKinematics(const Eigen::Ref<const Eigen::VectorXd>& q,
                         std::vector<geometry::Pose>* X_WL) const;
  /// The eye camera's optical frame in the world, from the links' poses.
  geometry::Pose CameraPose(int eye, const std::vector<geometry::Pose>& X_WL) const {
    return X_WL[cameras_[eye].link] * cameras_[eye].X_LC;
  }
  /// Whether every joint is within its limits.
  bool WithinLimits(const Eigen::Ref<const Eigen::VectorXd>& q) const;
  /// Throws InvalidArgument naming the first joint outside its limits, its value and range (in
  /// degrees for rotations), or a q of the wrong size or not finite.
  void CheckLimits(const Eigen::Ref<const Eigen::VectorXd>& q) const;

 private:
  HeadModel(std::string name, KinematicTree tree);

  std::string name_;
  KinematicTree tree_;
  std::shared_ptr<const JointNames> joint_names_;
  geometry::Pose X_WB_ = geometry::Pose::Identity();
  std::vector<JointSettings> joints_;
  std::array<EyeCamera, 2> cameras_;
  FixationRule rule_;
  std::vector<UrdfVisual> visuals_;
  std::string urdf_xml_;
  std::string source_;
  std::optional<HeadGeometry> appendix_a_;

  friend class HeadModelReader;
};

}  // namespace saccade::head
