#include "saccade/head/urdf_export.h"

#include <fmt/format.h>
#include <tinyxml.h>
#include <urdf_model/model.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <memory>

namespace saccade::head {
namespace {

using geometry::Pose;

// Below this |cos(pitch)| a rotation is at pitch = +-pi/2, where roll and yaw turn about the
// same axis: roll is set to 0 and the yaw takes the whole turn. cos(pitch) of an exact quarter
// turn computed in doubles is ~6e-17; a rotation this close to the lock moves a point at 1 m by
// less than 1e-10 m when it is written as the lock itself.
constexpr double kGimbalLock = 1e-10;
// Differences below this (pixels) change no projection measurably: a calibration's principal
// point within it of the centre, or fy within it of fx over the image, counts as Gazebo's.
constexpr double kPixelTolerance = 1e-9;
// The clip planes of a camera that has none (metres): close enough for a head's workspace.
constexpr double kDefaultNear = 0.02;
constexpr double kDefaultFar = 50.0;

// The shortest text that reads back as the same double ("0.1", "1e-05", "-1.5707963267948966");
// -0 as 0.
std::string Number(double value) { return fmt::format("{}", value + 0.0); }
std::string Numbers(const Eigen::Vector3d& v) {
  return fmt::format("{} {} {}", Number(v.x()), Number(v.y()), Number(v.z()));
}

// URDF's rpy (R = Rz(yaw) Ry(pitch) Rx(roll)) of a rotation, exact at the gimbal lock, where
// geometry::RpyFromRotation's atan2(0, 0) loses the turn (a camera frame on an optical link is
// one: Gazebo's x axis along the link's z).
Eigen::Vector3d Rpy(const Eigen::Matrix3d& R) {
  const double c = std::hypot(R(0, 0), R(1, 0));  // |cos(pitch)|
  if (c < kGimbalLock) {
    // R = [0, -sy, .; 0, cy, .; -sp, 0, 0] with roll = 0.
    return {0.0, R(2, 0) < 0 ? M_PI / 2 : -M_PI / 2, std::atan2(-R(0, 1), R(1, 1))};
  }
  return {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), c), std::atan2(R(1, 0), R(0, 0))};
}

// Gazebo's camera frame in the optical frame: the inverse of GazeboCamera::X_LOptical's turn.
Pose GazeboInOptical() {
  Eigen::Matrix3d R;
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return geometry::MakePose(R.transpose(), Eigen::Vector3d::Zero());
}

urdf::Pose ToUrdf(const Pose& X) {
  urdf::Pose pose;
  pose.position = urdf::Vector3(X.translation().x(), X.translation().y(), X.translation().z());
  const Eigen::Quaterniond q(X.linear());
  pose.rotation = urdf::Rotation(q.x(), q.y(), q.z(), q.w());
  return pose;
}

// The <limit> of a joint: the head's settings for an actuated joint, the tree's for a mimic.
urdf::JointLimitsSharedPtr Limits(const HeadModel& head, const KinematicTree::Joint& joint) {
  if (joint.type == JointType::kFixed) return nullptr;
  auto limits = std::make_shared<urdf::JointLimits>();
  limits->effort = 0.0;  // saccade models no torques; urdfdom requires the attribute
  if (!joint.is_mimic) {
    const JointSettings& s = head.joint(joint.variable);
    limits->lower = s.limits.min;
    limits->upper = s.limits.max;
    limits->velocity = s.limits.max_velocity;
  } else {
    limits->lower = joint.lower;
    limits->upper = joint.upper;
    limits->velocity = joint.max_velocity;
  }
  if (joint.type == JointType::kContinuous) {
    if (!(limits->velocity > 0.0)) return nullptr;
    limits->lower = limits->upper = 0.0;  // URDF ignores them on a continuous joint
  }
  return limits;
}

urdf::ModelInterface ToUrdfModel(const HeadModel& head) {
  const KinematicTree& tree = head.tree();
  urdf::ModelInterface model;
  model.name_ = head.name();
  for (int l = 0; l < tree.num_links(); ++l) {
    auto link = std::make_shared<urdf::Link>();
    link->name = tree.link_name(l);
    model.links_[link->name] = link;
  }
  model.root_link_ = model.links_[tree.link_name(tree.root())];
  for (int j = 0; j < tree.num_joints(); ++j) {
    const KinematicTree::Joint& joint = tree.joint(j);
    auto out = std::make_shared<urdf::Joint>();
    out->name = joint.name;
    switch (joint.type) {
      case JointType::kRevolute:
        out->type = urdf::Joint::REVOLUTE;
        break;
      case JointType::kContinuous:
        out->type = urdf::Joint::CONTINUOUS;
        break;
      case JointType::kPrismatic:
        out->type = urdf::Joint::PRISMATIC;
        break;
      case JointType::kFixed:
        out->type = urdf::Joint::FIXED;
        break;
    }
    out->parent_link_name = tree.link_name(joint.parent);
    out->child_link_name = tree.link_name(joint.child);
    out->parent_to_joint_origin_transform = ToUrdf(joint.X_PJ);
    out->axis = urdf::Vector3(joint.axis.x(), joint.axis.y(), joint.axis.z());
    out->limits = Limits(head, joint);
    if (joint.is_mimic) {
      out->mimic = std::make_shared<urdf::JointMimic>();
      out->mimic->joint_name = tree.variable_name(joint.variable);
      out->mimic->multiplier = joint.multiplier;
      out->mimic->offset = joint.offset;
    }
    model.joints_[out->name] = out;
  }
  return model;
}

TiXmlElement* Child(TiXmlElement* parent, const char* name) {
  TiXmlElement* e = parent->FirstChildElement(name);
  if (e == nullptr) e = parent->LinkEndChild(new TiXmlElement(name))->ToElement();
  return e;
}

// urdfdom writes 6 significant digits; every number is written again in full.
void WriteNumbers(const HeadModel& head, const KinematicTree::Joint& joint, TiXmlElement* e) {
  TiXmlElement* origin = Child(e, "origin");
  origin->SetAttribute("xyz", Numbers(joint.X_PJ.translation()));
  origin->SetAttribute("rpy", Numbers(Rpy(joint.X_PJ.linear())));
  if (joint.type != JointType::kFixed) Child(e, "axis")->SetAttribute("xyz", Numbers(joint.axis));
  if (const urdf::JointLimitsSharedPtr limits = Limits(head, joint)) {
    TiXmlElement* limit = Child(e, "limit");
    limit->SetAttribute("lower", Number(limits->lower));
    limit->SetAttribute("upper", Number(limits->upper));
    limit->SetAttribute("velocity", Number(limits->velocity));
  }
  if (joint.is_mimic) {
    TiXmlElement* mimic = Child(e, "mimic");
    mimic->SetAttribute("multiplier", Number(joint.multiplier));
    mimic->SetAttribute("offset", Number(joint.offset));
  }
}

// Moves the <link> and <joint> elements into the tree's order (urdfdom writes them by name),
// numbers in full.
void Reorder(const HeadModel& head, TiXmlElement* robot) {
  const KinematicTree& tree = head.tree();
  std::map<std::pair<std::string, std::string>, TiXmlElement*> elements;
  for (TiXmlElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    if (const char* name = e->Attribute("name")) elements[{e->ValueStr(), name}] = e;
  }
  const auto move_last = [&](const std::string& kind, const std::string& name) -> TiXmlElement* {
    TiXmlElement* e = elements.at({kind, name});
    TiXmlElement* copy = robot->InsertEndChild(*e)->ToElement();
    robot->RemoveChild(e);
    return copy;
  };
  for (int l = 0; l < tree.num_links(); ++l) move_last("link", tree.link_name(l));
  for (int j = 0; j < tree.num_joints(); ++j) {
    WriteNumbers(head, tree.joint(j), move_last("joint", tree.joint(j).name));
  }
}

TiXmlElement* TextElement(TiXmlElement* parent, const char* name, const std::string& text) {
  TiXmlElement* e = parent->LinkEndChild(new TiXmlElement(name))->ToElement();
  e->LinkEndChild(new TiXmlText(text));
  return e;
}

// One eye's <gazebo> block; what Gazebo's camera cannot express goes to `warnings` and to a
// comment in the <sensor>.
void AddGazeboCamera(const HeadModel& head, int eye, TiXmlElement* robot,
                     std::vector<std::string>* warnings) {
  const EyeCamera& camera = head.camera(eye);
  const std::string name = eye == 0 ? "left_camera" : "right_camera";
  const geometry::Intrinsics& k = camera.model.intrinsics();
  const geometry::Distortion& d = camera.model.distortion();
  std::vector<std::string> differs;
  const double cx = (k.width() - 1) / 2.0;
  const double cy = (k.height() - 1) / 2.0;
  if (std::abs(k.fx() - k.fy()) * std::max(k.width(), k.height()) / k.fx() > kPixelTolerance) {
    differs.push_back(fmt::format(
        "fx {} != fy {} px: Gazebo's pixels are square; written with fx (horizontal_fov)", k.fx(),
        k.fy()));
  }
  if (std::abs(k.cx() - cx) > kPixelTolerance || std::abs(k.cy() - cy) > kPixelTolerance) {
    differs.push_back(fmt::format(
        "principal point ({}, {}) px is not the image centre ({}, {}): Gazebo's is; written "
        "at the centre",
        k.cx(), k.cy(), cx, cy));
  }
  if (k.skew() != 0.0) {
    differs.push_back(fmt::format("skew {} px: Gazebo has none; written without", k.skew()));
  }
  std::vector<double> radtan;  // k1 k2 p1 p2 k3
  if (d.model() == geometry::DistortionModel::kFisheye) {
    differs.push_back(fmt::format(
        "fisheye (Kannala-Brandt) distortion k1..k4 = {}: Gazebo's camera has no such model; "
        "written without distortion",
        fmt::join(d.coefficients(), " ")));
  } else if (d.model() == geometry::DistortionModel::kRadialTangential && !d.IsIdentity()) {
    const std::vector<double>& c = d.coefficients();
    radtan.assign(c.begin(), c.begin() + 5);
    if (std::any_of(c.begin() + 5, c.end(), [](double v) { return v != 0.0; })) {
      differs.push_back(fmt::format(
          "rational distortion k4 k5 k6 = {}: Gazebo has k1 k2 k3 p1 p2 only; written without "
          "them",
          fmt::join(c.begin() + 5, c.end(), " ")));
    }
  }
  for (const std::string& what : differs) {
    warnings->push_back(
        fmt::format("{} camera (sensor {}): {}", eye == 0 ? "left" : "right", name, what));
  }

  TiXmlElement* gazebo = robot->LinkEndChild(new TiXmlElement("gazebo"))->ToElement();
  gazebo->SetAttribute("reference", head.tree().link_name(camera.link));
  TiXmlElement* sensor = gazebo->LinkEndChild(new TiXmlElement("sensor"))->ToElement();
  sensor->SetAttribute("type", "camera");
  sensor->SetAttribute("name", name);
  for (const std::string& what : differs) {
    sensor->LinkEndChild(new TiXmlComment((" not exact: " + what + " ").c_str()));
  }
  const Pose X_LS = camera.X_LC * GazeboInOptical();
  TextElement(sensor, "pose",
              fmt::format("{} {}", Numbers(X_LS.translation()), Numbers(Rpy(X_LS.linear()))));
  TiXmlElement* gz_camera = sensor->LinkEndChild(new TiXmlElement("camera"))->ToElement();
  TextElement(gz_camera, "horizontal_fov", Number(2.0 * std::atan(k.width() / 2.0 / k.fx())));
  TiXmlElement* image = gz_camera->LinkEndChild(new TiXmlElement("image"))->ToElement();
  TextElement(image, "width", std::to_string(k.width()));
  TextElement(image, "height", std::to_string(k.height()));
  TiXmlElement* clip = gz_camera->LinkEndChild(new TiXmlElement("clip"))->ToElement();
  const auto [near, far] = camera.clip.value_or(std::pair{kDefaultNear, kDefaultFar});
  TextElement(clip, "near", Number(near));
  TextElement(clip, "far", Number(far));
  if (!radtan.empty()) {
    TiXmlElement* distortion = gz_camera->LinkEndChild(new TiXmlElement("distortion"))->ToElement();
    TextElement(distortion, "k1", Number(radtan[0]));
    TextElement(distortion, "k2", Number(radtan[1]));
    TextElement(distortion, "k3", Number(radtan[4]));
    TextElement(distortion, "p1", Number(radtan[2]));
    TextElement(distortion, "p2", Number(radtan[3]));
    TextElement(distortion, "center", "0.5 0.5");
  }
}

}  // namespace

UrdfExport ExportUrdf(const HeadModel& head) {
  if (!head.urdf_xml().empty()) return {head.urdf_xml(), {}};
  UrdfExport result;
  const std::unique_ptr<TiXmlDocument> document(urdf::exportURDF(ToUrdfModel(head)));
  TiXmlElement* robot = document->RootElement();
  Reorder(head, robot);
  const Eigen::Vector3d rpy = Rpy(head.X_WB().linear());
  robot->InsertBeforeChild(
      robot->FirstChild(),
      TiXmlComment(fmt::format(" Written by `saccade urdf` from {}. The head file places the "
                               "root link {} in the world at position [{}], rpy [{}] (rad) ",
                               head.source().empty() ? head.name() : head.source(),
                               head.tree().link_name(head.tree().root()),
                               Numbers(head.X_WB().translation()), Numbers(rpy))
                       .c_str()));
  for (int eye = 0; eye < 2; ++eye) AddGazeboCamera(head, eye, robot, &result.warnings);
  document->InsertBeforeChild(document->FirstChild(), TiXmlDeclaration("1.0", "utf-8", ""));
  TiXmlPrinter printer;
  printer.SetIndent("  ");
  document->Accept(&printer);
  result.xml = printer.Str();
  return result;
}

}  // namespace saccade::head
