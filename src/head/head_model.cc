#include "saccade/head/head_model.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <set>

#include "core/internal_yaml.h"
#include "head/internal_head_yaml.h"
#include "saccade/core/error.h"
#include "saccade/core/units.h"
#include "saccade/geometry/calibration_io.h"

namespace saccade::head {

namespace fs = std::filesystem;
using geometry::Pose;
using saccade::internal::Entry;

namespace {

Pose Shift(double x, double y, double z) {
  Pose X = Pose::Identity();
  X.translation() = Eigen::Vector3d(x, y, z);
  return X;
}

// OpenCV's optical axes in a REP 103 frame (x forward, y left, z up): x = -y, y = -z, z = x.
Pose OpticalAxes(double ahead) {
  Eigen::Matrix3d R;
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return geometry::MakePose(R, Eigen::Vector3d(ahead, 0, 0));
}

JointSpec Legacy(const std::string& name, JointType type, const std::string& parent,
                 const std::string& child, const Pose& X_PJ, const Eigen::Vector3d& axis,
                 const JointLimits& limits) {
  JointSpec j;
  j.name = name;
  j.type = type;
  j.parent = parent;
  j.child = child;
  j.X_PJ = X_PJ;
  j.axis = axis;
  j.lower = limits.min;
  j.upper = limits.max;
  j.max_velocity = limits.max_velocity;
  return j;
}

// A map whose keys are names (joints, packages): any key, checked by the caller.
void RequireMap(const Entry& e, const char* what) {
  if (!e.IsMap()) e.Fail(fmt::format("expected {}, got {}", what, e.Describe()));
}

std::string Describe(double value, bool angular) {
  return angular ? fmt::format("{:.6g} deg", value * kRadToDeg) : fmt::format("{:.6g} m", value);
}

}  // namespace

// Reads the head file that names a URDF; a friend of HeadModel.
class HeadModelReader {
 public:
  HeadModelReader(const std::string& source, const fs::path& base_dir)
      : source_(source), base_dir_(base_dir) {}

  HeadModel Read(const YAML::Node& root) const {
    const Entry top(root, "", &source_);
    top.ExpectMap({"name", "urdf", "pose", "visuals", "packages", "cameras", "joints", "fixation"});
    UrdfOptions options;
    if (const auto visuals = top.Find("visuals")) {
      const std::string value = visuals->AsString();
      if (value != "required" && value != "optional") {
        visuals->Fail("expected 'required' or 'optional', got '" + value + "'");
      }
      options.visuals_optional = value == "optional";
    }
    if (const auto packages = top.Find("packages")) {
      RequireMap(*packages, "a map of package name to folder");
      for (const auto& item : packages->node()) {
        const std::string name = item.first.as<std::string>();
        options.packages[name] = base_dir_ / packages->Get(name.c_str()).AsNonEmptyString();
      }
    }
    const Entry urdf_entry = top.Get("urdf");
    const fs::path urdf_path = base_dir_ / urdf_entry.AsNonEmptyString();
    if (!fs::is_regular_file(urdf_path)) {
      urdf_entry.Fail(fmt::format("the URDF file {} does not exist", urdf_path.string()));
    }
    UrdfModel urdf = LoadUrdfFile(urdf_path, options);
    const auto name_entry = top.Find("name");
    HeadModel head(name_entry ? name_entry->AsNonEmptyString() : urdf.name, urdf.tree);
    head.source_ = source_;
    head.urdf_xml_ = urdf.xml;
    head.visuals_ = urdf.visuals;
    if (const auto pose = top.Find("pose")) head.X_WB_ = internal::ReadPose(*pose);
    ReadJoints(top.Find("joints"), top, urdf.source, &head);
    ReadCameras(top.Get("cameras"), urdf, &head);
    ReadRule(top.Find("fixation"), &head);
    return head;
  }

 private:
  // The URDF's limits, a mimic's own limits folded into its source's. Throws FileError naming the
  // URDF and the mimic when that leaves its source no value (no posture would respect both).
  static std::vector<JointSettings> UrdfSettings(const KinematicTree& tree,
                                                 const std::string& urdf_source) {
    std::vector<JointSettings> settings(tree.num_variables());
    for (int i = 0; i < tree.num_variables(); ++i) {
      const KinematicTree::Joint& joint = tree.joint(tree.variable_joint(i));
      settings[i].limits.min = joint.lower;
      settings[i].limits.max = joint.upper;
      settings[i].limits.max_velocity = joint.max_velocity;
    }
    for (int j = 0; j < tree.num_joints(); ++j) {
      const KinematicTree::Joint& joint = tree.joint(j);
      if (!joint.is_mimic || joint.multiplier == 0.0) continue;
      JointLimits& limits = settings[joint.variable].limits;
      double a = (joint.lower - joint.offset) / joint.multiplier;
      double b = (joint.upper - joint.offset) / joint.multiplier;
      if (a > b) std::swap(a, b);
      if (a > limits.max || b < limits.min) {
        const std::string& source_name = tree.variable_name(joint.variable);
        throw FileError(
            urdf_source, 0, fmt::format("joint {}", joint.name),
            fmt::format("its limits [{}, {}] as a mimic of '{}' (multiplier {}, offset {}) allow "
                        "'{}' only [{}, {}], outside its own limits [{}, {}]; expected ranges "
                        "that overlap",
                        joint.lower, joint.upper, source_name, joint.multiplier, joint.offset,
                        source_name, a, b, limits.min, limits.max));
      }
      limits.min = std::max(limits.min, a);
      limits.max = std::min(limits.max, b);
    }
    return settings;
  }

  void ReadJoints(const std::optional<Entry>& joints, const Entry& top,
                  const std::string& urdf_source, HeadModel* head) const {
    const KinematicTree& tree = head->tree_;
    head->joints_ = UrdfSettings(tree, urdf_source);
    std::map<int, std::string> servo_ids;
    if (joints) {
      RequireMap(*joints, "a map of joint name to settings");
      for (const auto& item : joints->node()) {
        const std::string name = item.first.as<std::string>();
        const Entry e = joints->Get(name.c_str());
        const int i = tree.FindVariable(name);
        if (i < 0) {
          const int j = tree.FindJoint(name);
          e.Fail(j < 0 ? fmt::format("the URDF has no joint '{}'", name)
                       : fmt::format("joint '{}' is {}: only actuated joints have settings", name,
                                     tree.joint(j).is_mimic ? "a mimic" : "fixed"));
        }
        ReadJoint(e, tree.joint(tree.variable_joint(i)), &head->joints_[i]);
        if (const auto& servo = head->joints_[i].servo) {
          if (!servo_ids.emplace(servo->id, name).second) {
            e.Get("servo").Get("id").Fail(
                fmt::format("servo id {} is already joint {}'s", servo->id, servo_ids[servo->id]));
          }
        }
      }
    }
    for (int i = 0; i < head->num_joints(); ++i) {
      const JointSettings& s = head->joints_[i];
      if (!s.driven) continue;
      const std::string where = fmt::format("joints.{}", tree.variable_name(i));
      if (!(s.limits.max_velocity > 0.0)) {
        throw FileError(source_, top.line(), where,
                        "a driven joint needs a velocity limit: the URDF's <limit velocity> or "
                        "max_velocity_deg here");
      }
      if (!(s.limits.max_acceleration > 0.0)) {
        throw FileError(source_, top.line(), where,
                        "a driven joint needs max_acceleration_deg (or max_acceleration): a URDF "
                        "has no acceleration limits");
      }
    }
  }

  static void ReadJoint(const Entry& e, const KinematicTree::Joint& joint, JointSettings* s) {
    e.ExpectMap({"driven", "hold", "hold_deg", "limits", "limits_deg", "max_velocity",
                 "max_velocity_deg", "max_acceleration", "max_acceleration_deg", "servo"});
    const bool angular = joint.type != JointType::kPrismatic;
    for (const char* key : {"hold_deg", "limits_deg", "max_velocity_deg", "max_acceleration_deg"}) {
      if (!angular && e.Has(key)) {
        e.Get(key).Fail("the joint is prismatic: give it in metres, without _deg");
      }
    }
    if (const auto driven = e.Find("driven")) s->driven = driven->AsBool();
    bool degrees = false;
    if (const auto range = internal::FindAngleEntry(e, "limits", &degrees)) {
      const std::vector<double> v = range->AsDoubles(2);
      const double scale = degrees ? kDegToRad : 1.0;
      const double lower = v[0] * scale;
      const double upper = v[1] * scale;
      if (!(lower <= upper)) range->Fail("expected [min, max] with min <= max");
      // Degrees round-trip through radians: allow the last bits.
      const double slack = 1e-12 * std::max(1.0, std::abs(lower) + std::abs(upper));
      if (lower < s->limits.min - slack || upper > s->limits.max + slack) {
        range->Fail(
            fmt::format("[{}, {}] is wider than the URDF's [{}, {}]; the head file may "
                        "only narrow a joint's range",
                        Describe(lower, angular), Describe(upper, angular),
                        Describe(s->limits.min, angular), Describe(s->limits.max, angular)));
      }
      s->limits.min = std::max(lower, s->limits.min);
      s->limits.max = std::min(upper, s->limits.max);
    }
    if (const auto v = internal::FindAngle(e, "max_velocity")) {
      if (!(*v > 0.0)) e.Fail("max_velocity must be > 0");
      s->limits.max_velocity = *v;
    }
    if (const auto a = internal::FindAngle(e, "max_acceleration")) {
      if (!(*a > 0.0)) e.Fail("max_acceleration must be > 0");
      s->limits.max_acceleration = *a;
    }
    if (const auto hold = internal::FindAngleEntry(e, "hold", &degrees)) {
      s->hold = hold->AsDouble() * (degrees ? kDegToRad : 1.0);
      if (!s->limits.Contains(s->hold)) {
        hold->Fail(fmt::format("{} is outside the joint's range [{}, {}]",
                               Describe(s->hold, angular), Describe(s->limits.min, angular),
                               Describe(s->limits.max, angular)));
      }
    }
    if (const auto servo = e.Find("servo")) s->servo = internal::ReadServo(*servo);
  }

  void ReadCameras(const Entry& cameras, const UrdfModel& urdf, HeadModel* head) const {
    cameras.ExpectMap({"left", "right"});
    for (int eye = 0; eye < 2; ++eye) {
      const Entry e = cameras.Get(eye == 0 ? "left" : "right");
      EyeCamera& camera = head->cameras_[eye];
      const auto sensor = e.Find("gazebo_sensor");
      const auto link = e.Find("link");
      if (sensor.has_value() == link.has_value()) {
        e.Fail(
            "give either gazebo_sensor (a <sensor type=\"camera\"> of the URDF) or link (an "
            "optical-frame link) with the intrinsics");
      }
      const auto calibration = e.Find("calibration");
      if (sensor) {
        e.ExpectMap({"gazebo_sensor", "calibration"});
        const GazeboCamera* gazebo = urdf.FindCamera(sensor->AsNonEmptyString());
        if (gazebo == nullptr) {
          std::string names;
          for (const GazeboCamera& c : urdf.cameras) names += (names.empty() ? "" : ", ") + c.name;
          sensor->Fail(fmt::format("the URDF has no camera sensor '{}' (it has: {})",
                                   sensor->AsString(), names.empty() ? "none" : names));
        }
        camera.link = gazebo->link_index;
        camera.X_LC = gazebo->X_LOptical();
        camera.model = gazebo->Model();
        camera.clip = std::pair{gazebo->near, gazebo->far};
      } else {
        camera.link = head->tree_.FindLink(link->AsNonEmptyString());
        if (camera.link < 0) {
          link->Fail(fmt::format("the URDF has no link '{}'", link->AsString()));
        }
        if (calibration && !e.Has("width")) {
          e.ExpectMap({"link", "calibration"});
        } else {
          camera.model = internal::ReadCamera(e, {"link", "calibration"});
        }
      }
      if (calibration) {
        const fs::path path = base_dir_ / calibration->AsNonEmptyString();
        camera.model = geometry::ReadCameraCalibration(path).model;
      }
    }
  }

  int Joint(const Entry& e, const KinematicTree& tree) const {
    const std::string name = e.AsNonEmptyString();
    const int i = tree.FindVariable(name);
    if (i < 0) e.Fail(fmt::format("'{}' is not an actuated joint of the URDF", name));
    return i;
  }

  void ReadRule(const std::optional<Entry>& e, HeadModel* head) const {
    const int n = head->num_joints();
    FixationRule& rule = head->rule_;
    rule.hold.assign(n, false);
    rule.weights = Eigen::VectorXd::Ones(n);
    rule.preferred = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < n; ++i) rule.hold[i] = !head->joints_[i].driven;
    if (!e) return;
    e->ExpectMap({"hold", "weights", "preferred", "preferred_deg", "symmetric"});
    const KinematicTree& tree = head->tree_;
    if (const auto hold = e->Find("hold")) {
      for (const Entry& name : hold->AsSequence("a list of joint names")) {
        rule.hold[Joint(name, tree)] = true;
      }
    }
    if (const auto weights = e->Find("weights")) {
      RequireMap(*weights, "a map of joint name to weight");
      for (const auto& item : weights->node()) {
        const Entry w = weights->Get(item.first.as<std::string>().c_str());
        const Entry name(item.first, w.path(), &source_, w.line());
        rule.weights[Joint(name, tree)] = w.AsPositive();
      }
    }
    bool degrees = false;
    if (const auto preferred = internal::FindAngleEntry(*e, "preferred", &degrees)) {
      RequireMap(*preferred, "a map of joint name to value");
      for (const auto& item : preferred->node()) {
        const Entry v = preferred->Get(item.first.as<std::string>().c_str());
        const Entry name(item.first, v.path(), &source_, v.line());
        rule.preferred[Joint(name, tree)] = v.AsDouble() * (degrees ? kDegToRad : 1.0);
      }
    }
    if (const auto symmetric = e->Find("symmetric")) {
      for (const Entry& pair : symmetric->AsSequence("a list of [joint, joint, sign]")) {
        const std::vector<Entry> items = pair.AsSequence("[joint, joint, sign]");
        if (items.size() != 3) pair.Fail("expected [joint_a, joint_b, sign] (q_b = sign * q_a)");
        FixationRule::Pair p{Joint(items[0], tree), Joint(items[1], tree), items[2].AsDouble()};
        if (p.a == p.b || p.sign == 0.0) pair.Fail("expected two different joints and sign != 0");
        rule.symmetric.push_back(p);
      }
    }
  }

  const std::string& source_;
  fs::path base_dir_;
};

HeadModel::HeadModel(std::string name, KinematicTree tree)
    : name_(std::move(name)), tree_(std::move(tree)) {
  auto names = std::make_shared<JointNames>();
  for (int i = 0; i < tree_.num_variables(); ++i) names->push_back(tree_.variable_name(i));
  joint_names_ = std::move(names);
}

JointState HeadModel::Arrange(const JointState& joints) const {
  if (joints.shared_names() == joint_names_ || joints.names() == *joint_names_) {
    return State(joints.values());
  }
  return joints.ArrangedAs(joint_names_);
}

Eigen::VectorXd HeadModel::Posture(const JointState& joints) const {
  if (joints.empty()) return HomePosture();
  if (joints.shared_names() == joint_names_ || joints.names() == *joint_names_) {
    return joints.values();
  }
  return joints.ArrangedAs(joint_names_).values();
}

HeadModel HeadModel::FromDescription(const HeadDescription& legacy) {
  const HeadGeometry& g = legacy.geometry();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const JointLimits fixed;
  const std::vector<JointSpec> joints = {
      Legacy("pan", JointType::kRevolute, "base_link", "neck_link", Pose::Identity(), z,
             legacy.limits(Joint::kPan)),
      Legacy("tilt", JointType::kRevolute, "neck_link", "tilt_link", Shift(0, 0, g.D),
             Eigen::Vector3d::UnitY(), legacy.limits(Joint::kTilt)),
      Legacy("cyclopean", JointType::kFixed, "tilt_link", "cyclopean_link", Shift(0, 0, g.H), z,
             fixed),
      Legacy("left", JointType::kRevolute, "cyclopean_link", "left_eye_link", Shift(0, g.B, 0), z,
             legacy.limits(Joint::kLeft)),
      Legacy("right", JointType::kRevolute, "cyclopean_link", "right_eye_link", Shift(0, -g.B, 0),
             z, legacy.limits(Joint::kRight)),
      Legacy("left_optical", JointType::kFixed, "left_eye_link", "left_camera_optical",
             OpticalAxes(g.delta_l), z, fixed),
      Legacy("right_optical", JointType::kFixed, "right_eye_link", "right_camera_optical",
             OpticalAxes(g.delta_r), z, fixed)};
  const std::vector<std::string> links = {
      "base_link",     "neck_link",      "tilt_link",           "cyclopean_link",
      "left_eye_link", "right_eye_link", "left_camera_optical", "right_camera_optical"};
  HeadModel head(legacy.name(), KinematicTree::Build(links, joints, legacy.name()));
  head.X_WB_ = legacy.X_WB();
  head.appendix_a_ = g;
  for (const Joint j : kAllJoints) {
    JointSettings s;
    s.limits = legacy.limits(j);
    s.servo = legacy.servo(j);
    head.joints_.push_back(s);
  }
  head.cameras_[0] = {head.tree_.FindLink("left_camera_optical"), Pose::Identity(),
                      legacy.left_camera(), std::nullopt};
  head.cameras_[1] = {head.tree_.FindLink("right_camera_optical"), Pose::Identity(),
                      legacy.right_camera(), std::nullopt};
  head.rule_.hold.assign(4, false);
  head.rule_.weights = Eigen::VectorXd::Ones(4);
  head.rule_.preferred = Eigen::VectorXd::Zero(4);
  head.rule_.symmetric = {{static_cast<int>(Joint::kLeft), static_cast<int>(Joint::kRight), -1.0}};
  return head;
}

HeadModel HeadModel::FromYamlString(const std::string& text, const std::string& source,
                                    const fs::path& base_dir) {
  const YAML::Node root = saccade::internal::ParseYaml(text, source);
  if (!root.IsMap() || !root["urdf"]) {
    HeadModel head = FromDescription(HeadDescription::FromYamlString(text, source));
    head.source_ = source;
    return head;
  }
  try {
    return HeadModelReader(source, base_dir).Read(root);
  } catch (const FileError&) {
    throw;
  } catch (const YAML::Exception& error) {
    throw FileError(source, error.mark.is_null() ? 0 : error.mark.line + 1, "", error.msg);
  }
}

HeadModel HeadModel::FromFile(const fs::path& path) {
  return FromYamlString(saccade::internal::ReadConfigFile(path, "head file"), path.string(),
                        path.parent_path());
}

std::optional<HeadDescription> HeadModel::AppendixAHead() const {
  if (!appendix_a_) return std::nullopt;
  std::array<JointLimits, 4> limits;
  std::array<std::optional<ServoMapping>, 4> servos;
  for (int i = 0; i < 4; ++i) {
    limits[i] = joints_[i].limits;
    servos[i] = joints_[i].servo;
  }
  return HeadDescription(name_, *appendix_a_, limits, X_WB_, cameras_[0].model, cameras_[1].model,
                         servos);
}

std::array<geometry::Pose, 2> HeadModel::CameraPoses(const JointState& joints) const {
  std::vector<geometry::Pose> X_WL;
  ForwardKinematics(Posture(joints), &X_WL);
  return {CameraPose(0, X_WL), CameraPose(1, X_WL)};
}

HeadModel HeadModel::WithPose(const geometry::Pose& X_WB) const {
  HeadModel head = *this;
  head.X_WB_ = X_WB;
  return head;
}

HeadModel HeadModel::WithCamera(int eye, const geometry::CameraModel& model) const {
  HeadModel head = *this;
  head.cameras_[eye].model = model;
  return head;
}

Eigen::VectorXd HeadModel::HomePosture() const {
  Eigen::VectorXd q(num_joints());
  for (int i = 0; i < num_joints(); ++i) {
    const JointSettings& s = joints_[i];
    q[i] = s.driven ? std::clamp(0.0, s.limits.min, s.limits.max) : s.hold;
  }
  return q;
}

void HeadModel::ForwardKinematics(const Eigen::Ref<const Eigen::VectorXd>& q,
                                  std::vector<geometry::Pose>* X_WL) const {
  tree_.ForwardKinematics(q, X_WB_, X_WL);
}

bool HeadModel::WithinLimits(const Eigen::Ref<const Eigen::VectorXd>& q) const {
  if (q.size() != num_joints()) return false;
  for (int i = 0; i < num_joints(); ++i) {
    if (!joints_[i].limits.Contains(q[i])) return false;
  }
  return true;
}

void HeadModel::CheckLimits(const Eigen::Ref<const Eigen::VectorXd>& q) const {
  if (q.size() != num_joints()) {
    throw InvalidArgument(
        fmt::format("head {}: expected {} joint values, got {}", name_, num_joints(), q.size()));
  }
  for (int i = 0; i < num_joints(); ++i) {
    const JointLimits& l = joints_[i].limits;
    if (l.Contains(q[i])) continue;
    const bool angular = tree_.joint(tree_.variable_joint(i)).type != JointType::kPrismatic;
    throw InvalidArgument(fmt::format("joint {}: {} is outside its limits [{}, {}]", joint_name(i),
                                      Describe(q[i], angular), Describe(l.min, angular),
                                      Describe(l.max, angular)));
  }
}

}  // namespace saccade::head
