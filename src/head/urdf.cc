#include "saccade/head/urdf.h"

#include <console_bridge/console.h>
#include <fmt/format.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <sstream>

#include "saccade/core/error.h"
#include "saccade/core/log.h"

namespace saccade::head {
namespace {

namespace fs = std::filesystem;
using geometry::Pose;

// urdfdom reports through console_bridge's one global handler; this one keeps the messages of
// one parse (a mutex makes parses from several threads take turns).
class CapturedConsole : public console_bridge::OutputHandler {
 public:
  CapturedConsole() { console_bridge::useOutputHandler(this); }
  ~CapturedConsole() override { console_bridge::restorePreviousOutputHandler(); }
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      errors_ += (errors_.empty() ? "" : "; ") + text;
    }
  }
  const std::string& errors() const { return errors_; }

 private:
  std::string errors_;
};
std::mutex console_mutex;

Pose ToPose(const urdf::Pose& pose) {
  const Eigen::Quaterniond q(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z);
  Pose X = Pose::Identity();
  X.linear() = q.toRotationMatrix();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return X;
}

// The lines of the <robot>'s direct <link> and <joint> elements, and the joints' order.
struct ElementLines {
  std::vector<std::string> links;
  std::vector<int> link_lines;
  std::vector<std::string> joints;
  std::map<std::string, int> joint_lines;
  /// The joints' edges: joint, parent link, child link.
  struct Edge {
    std::string joint, parent, child;
  };
  std::vector<Edge> edges;
  int Line(const std::string& joint) const {
    const auto it = joint_lines.find(joint);
    return it == joint_lines.end() ? 0 : it->second;
  }
};

ElementLines ScanElements(const TiXmlElement& robot) {
  ElementLines lines;
  for (const TiXmlElement* e = robot.FirstChildElement(); e; e = e->NextSiblingElement()) {
    const char* name = e->Attribute("name");
    if (name == nullptr) continue;
    if (e->ValueStr() == "link") {
      lines.links.emplace_back(name);
      lines.link_lines.push_back(e->Row());
    } else if (e->ValueStr() == "joint") {
      lines.joints.emplace_back(name);
      lines.joint_lines.emplace(name, e->Row());
      const TiXmlElement* parent = e->FirstChildElement("parent");
      const TiXmlElement* child = e->FirstChildElement("child");
      const char* parent_link = parent ? parent->Attribute("link") : nullptr;
      const char* child_link = child ? child->Attribute("link") : nullptr;
      if (parent_link && child_link) lines.edges.push_back({name, parent_link, child_link});
    }
  }
  return lines;
}

JointSpec ToJointSpec(const urdf::Joint& joint, const std::string& source, int line) {
  JointSpec spec;
  spec.name = joint.name;
  spec.line = line;
  switch (joint.type) {
    case urdf::Joint::REVOLUTE:
      spec.type = JointType::kRevolute;
      break;
    case urdf::Joint::CONTINUOUS:
      spec.type = JointType::kContinuous;
      break;
    case urdf::Joint::PRISMATIC:
      spec.type = JointType::kPrismatic;
      break;
    case urdf::Joint::FIXED:
      spec.type = JointType::kFixed;
      break;
    default:
      throw FileError(source, line, fmt::format("joint {}", joint.name),
                      "its type is not supported; expected revolute, continuous, prismatic or "
                      "fixed (a head has no floating or planar joints)");
  }
  spec.parent = joint.parent_link_name;
  spec.child = joint.child_link_name;
  spec.X_PJ = ToPose(joint.parent_to_joint_origin_transform);
  spec.axis = Eigen::Vector3d(joint.axis.x, joint.axis.y, joint.axis.z);
  if (joint.limits) {
    spec.lower = joint.limits->lower;
    spec.upper = joint.limits->upper;
    spec.max_velocity = joint.limits->velocity;
  }
  if (joint.mimic) {
    spec.mimic = MimicSpec{joint.mimic->joint_name, joint.mimic->multiplier, joint.mimic->offset};
  }
  return spec;
}

// urdfdom links a cycle of joints into a cycle of shared pointers that it never frees (a leak
// per parse), and reports it only as "no root link": a cycle is refused before urdfdom reads it,
// naming its joints.
void RefuseCycles(const std::string& source, const ElementLines& lines) {
  std::map<std::string, std::vector<const ElementLines::Edge*>> out;
  for (const ElementLines::Edge& e : lines.edges) out[e.parent].push_back(&e);
  // Depth-first, iterative (a fuzzed file may chain thousands of links): 1 on the path, 2 done.
  std::map<std::string, int> state;
  for (const auto& [start, ignored] : out) {
    if (state[start] != 0) continue;
    std::vector<std::pair<const ElementLines::Edge*, size_t>> path = {{nullptr, 0}};
    std::vector<std::string> nodes = {start};
    state[start] = 1;
    while (!path.empty()) {
      auto& [edge, next] = path.back();
      const auto& children = out[nodes.back()];
      if (next == children.size()) {
        state[nodes.back()] = 2;
        path.pop_back();
        nodes.pop_back();
        continue;
      }
      const ElementLines::Edge* e = children[next++];
      if (state[e->child] == 1) {
        const auto first = std::find(nodes.begin(), nodes.end(), e->child);
        std::vector<std::string> cycle(first, nodes.end());
        cycle.push_back(e->child);
        throw FileError(source, lines.Line(e->joint), fmt::format("joint {}", e->joint),
                        fmt::format("the joints form a cycle of links ({}); expected a tree",
                                    fmt::join(cycle, " -> ")));
      }
      if (state[e->child] == 0) {
        state[e->child] = 1;
        path.push_back({e, 0});
        nodes.push_back(e->child);
      }
    }
  }
}

// urdfdom's messages name the element as "joint [NAME]" or "link [NAME]" but give no line: the
// error takes the element's line from the scan.
[[noreturn]] void ThrowUrdfdomError(const std::string& source, const ElementLines& lines,
                                    const std::string& errors) {
  const std::string what =
      fmt::format("urdfdom cannot read it: {}", errors.empty() ? "no reason given" : errors);
  // The joint first: "child link [skull] of joint [tilt] not found" is the joint's fault.
  for (const std::string kind : {"joint", "link"}) {
    // "<kind> [NAME]", either case of the kind's first letter (urdfdom writes both). Plain
    // string search: std::regex trips GCC 12's -Wmaybe-uninitialized under the sanitizers.
    std::string name;
    const std::string capital =
        std::string(1, static_cast<char>(kind[0] - 'a' + 'A')) + kind.substr(1);
    for (const std::string& prefix : {kind + " [", capital + " ["}) {
      const size_t at = errors.find(prefix);
      if (at == std::string::npos) continue;
      const size_t end = errors.find(']', at + prefix.size());
      if (end != std::string::npos) {
        name = errors.substr(at + prefix.size(), end - at - prefix.size());
      }
      break;
    }
    if (name.empty()) continue;
    int line = kind == "joint" ? lines.Line(name) : 0;
    if (kind == "link") {
      for (size_t l = 0; l < lines.links.size(); ++l) {
        if (lines.links[l] == name) line = lines.link_lines[l];
      }
    }
    throw FileError(source, line, fmt::format("{} {}", kind, name), what);
  }
  throw FileError(source, 0, "robot", what);
}

std::vector<std::string> SplitPath(const char* variable) {
  std::vector<std::string> dirs;
  const char* value = std::getenv(variable);
  if (value == nullptr) return dirs;
  std::stringstream stream(value);
  for (std::string dir; std::getline(stream, dir, ':');) {
    if (!dir.empty()) dirs.push_back(dir);
  }
  return dirs;
}

// ---------------------------------------------------------------------------------------
// Gazebo's camera blocks.

class GazeboReader {
 public:
  GazeboReader(const std::string& source, const KinematicTree& tree)
      : source_(source), tree_(tree) {}

  void Read(const TiXmlElement& robot, std::vector<GazeboCamera>* cameras) const {
    for (const TiXmlElement* g = robot.FirstChildElement("gazebo"); g;
         g = g->NextSiblingElement("gazebo")) {
      for (const TiXmlElement* s = g->FirstChildElement("sensor"); s;
           s = s->NextSiblingElement("sensor")) {
        const char* type = s->Attribute("type");
        if (type == nullptr || std::string(type) != "camera") continue;
        cameras->push_back(ReadCamera(*g, *s));
      }
    }
  }

 private:
  [[noreturn]] void Fail(const TiXmlElement& e, const std::string& key,
                         const std::string& what) const {
    throw FileError(source_, e.Row(), key, what);
  }

  std::vector<double> Numbers(const TiXmlElement& e, const std::string& key, size_t count) const {
    const char* text = e.GetText();
    std::vector<double> values;
    std::stringstream stream(text ? text : "");
    for (std::string word; stream >> word;) {
      char* end = nullptr;
      const double v = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0' || !std::isfinite(v)) {
        Fail(e, key, fmt::format("\"{}\" is not a finite number", word));
      }
      values.push_back(v);
    }
    if (values.size() != count) {
      Fail(
          e, key,
          fmt::format("expected {} number{}, got {}", count, count == 1 ? "" : "s", values.size()));
    }
    return values;
  }

  // The number in the child at `path` (e.g. {"image", "width"}); std::nullopt when absent.
  std::optional<double> Child(const TiXmlElement& e, std::initializer_list<const char*> path,
                              const std::string& key) const {
    const TiXmlElement* c = &e;
    for (const char* name : path) {
      c = c->FirstChildElement(name);
      if (c == nullptr) return std::nullopt;
    }
    return Numbers(*c, key, 1)[0];
  }

  GazeboCamera ReadCamera(const TiXmlElement& gazebo, const TiXmlElement& sensor) const {
    GazeboCamera c;
    const char* name = sensor.Attribute("name");
    c.name = name ? name : "";
    c.line = sensor.Row();
    const std::string key = fmt::format("gazebo sensor {}", c.name);
    const char* reference = gazebo.Attribute("reference");
    if (reference == nullptr) {
      Fail(gazebo, key,
           "the <gazebo> block has no reference=\"LINK\"; expected the link the "
           "camera is fixed to");
    }
    c.link = reference;
    c.link_index = tree_.FindLink(c.link);
    if (c.link_index < 0) {
      Fail(gazebo, key, fmt::format("its reference link \"{}\" does not exist", c.link));
    }
    if (const TiXmlElement* pose = sensor.FirstChildElement("pose")) {
      const std::vector<double> v = Numbers(*pose, key + " pose", 6);
      c.X_LS = geometry::MakePose(geometry::RotationFromRpy(v[3], v[4], v[5]),
                                  Eigen::Vector3d(v[0], v[1], v[2]));
    }
    const TiXmlElement* camera = sensor.FirstChildElement("camera");
    if (camera == nullptr) Fail(sensor, key, "it has no <camera> element");
    const auto fov = Child(*camera, {"horizontal_fov"}, key + " horizontal_fov");
    if (!fov || !(*fov > 0.0 && *fov < M_PI)) {
      Fail(*camera, key + " horizontal_fov",
           "expected <horizontal_fov> in radians, in (0, pi) (a pinhole camera)");
    }
    c.horizontal_fov = *fov;
    const auto width = Child(*camera, {"image", "width"}, key + " image width");
    const auto height = Child(*camera, {"image", "height"}, key + " image height");
    for (const auto& [value, what] : {std::pair{width, "width"}, {height, "height"}}) {
      if (!value || !(*value >= 1.0) || *value != std::floor(*value) || *value > 65535) {
        Fail(*camera, fmt::format("{} image {}", key, what),
             fmt::format("expected <image><{}> in pixels, a whole number >= 1", what));
      }
    }
    c.width = static_cast<int>(*width);
    c.height = static_cast<int>(*height);
    c.near = Child(*camera, {"clip", "near"}, key + " clip near").value_or(c.near);
    c.far = Child(*camera, {"clip", "far"}, key + " clip far").value_or(c.far);
    if (!(c.near > 0.0 && c.far > c.near)) {
      Fail(*camera, key + " clip",
           fmt::format("expected 0 < near < far, got near {} and far {}", c.near, c.far));
    }
    if (const TiXmlElement* d = camera->FirstChildElement("distortion"))
      ReadDistortion(*d, key, &c);
    return c;
  }

  void ReadDistortion(const TiXmlElement& d, const std::string& key, GazeboCamera* c) const {
    const char* names[] = {"k1", "k2", "p1", "p2", "k3"};
    for (int i = 0; i < 5; ++i) {
      c->distortion[i] = Child(d, {names[i]}, key + " distortion " + names[i]).value_or(0.0);
    }
    if (const TiXmlElement* center = d.FirstChildElement("center")) {
      const std::vector<double> v = Numbers(*center, key + " distortion center", 2);
      if (v[0] != 0.5 || v[1] != 0.5) {
        Fail(*center, key + " distortion center",
             fmt::format("got {} {}; saccade supports the image centre, 0.5 0.5", v[0], v[1]));
      }
    }
  }

  const std::string& source_;
  const KinematicTree& tree_;
};

// ---------------------------------------------------------------------------------------
// Visuals.

std::optional<Eigen::Vector4d> Colour(const urdf::Visual& visual) {
  if (!visual.material) return std::nullopt;
  const urdf::Color& c = visual.material->color;
  return Eigen::Vector4d(c.r, c.g, c.b, c.a);
}

std::vector<UrdfVisual> ReadVisuals(const urdf::ModelInterface& model, const KinematicTree& tree,
                                    const ElementLines& lines, const std::string& source,
                                    const fs::path& base_dir, const UrdfOptions& options) {
  std::vector<UrdfVisual> visuals;
  for (int l = 0; l < tree.num_links(); ++l) {
    const urdf::LinkConstSharedPtr link = model.getLink(tree.link_name(l));
    for (const urdf::VisualSharedPtr& v : link->visual_array) {
      if (!v || !v->geometry) continue;
      UrdfVisual visual;
      visual.link = l;
      visual.X_LV = ToPose(v->origin);
      visual.rgba = Colour(*v);
      visual.material = v->material_name;
      switch (v->geometry->type) {
        case urdf::Geometry::BOX: {
          const auto& box = static_cast<const urdf::Box&>(*v->geometry);
          visual.shape = UrdfVisual::Shape::kBox;
          visual.size = Eigen::Vector3d(box.dim.x, box.dim.y, box.dim.z);
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& cylinder = static_cast<const urdf::Cylinder&>(*v->geometry);
          visual.shape = UrdfVisual::Shape::kCylinder;
          visual.size = Eigen::Vector3d(cylinder.radius, cylinder.radius, cylinder.length);
          break;
        }
        case urdf::Geometry::SPHERE: {
          const auto& sphere = static_cast<const urdf::Sphere&>(*v->geometry);
          visual.shape = UrdfVisual::Shape::kSphere;
          visual.size = Eigen::Vector3d::Constant(sphere.radius);
          break;
        }
        case urdf::Geometry::MESH: {
          const auto& mesh = static_cast<const urdf::Mesh&>(*v->geometry);
          visual.shape = UrdfVisual::Shape::kMesh;
          visual.mesh_uri = mesh.filename;
          visual.scale = Eigen::Vector3d(mesh.scale.x, mesh.scale.y, mesh.scale.z);
          std::vector<std::string> searched;
          const auto path = ResolveMeshUri(mesh.filename, base_dir, options, &searched);
          if (!path) {
            const std::string what = fmt::format(
                "mesh \"{}\" not found (looked for {}); expected a mesh file there, or "
                "`visuals: optional` in the head file",
                mesh.filename, fmt::join(searched, ", "));
            if (!options.visuals_optional) {
              throw FileError(source, lines.link_lines[l],
                              fmt::format("link {} visual", tree.link_name(l)), what);
            }
            log::Log(log::Level::kWarn, "{}: link {}: {}; the visual is left out", source,
                     tree.link_name(l), what);
            continue;
          }
          visual.mesh_path = *path;
          break;
        }
      }
      visuals.push_back(visual);
    }
  }
  return visuals;
}

}  // namespace

geometry::CameraModel GazeboCamera::Model() const {
  const double f = width / 2.0 / std::tan(horizontal_fov / 2.0);
  const geometry::Intrinsics intrinsics(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0);
  const bool distorted =
      std::any_of(distortion.begin(), distortion.end(), [](double k) { return k != 0.0; });
  return geometry::CameraModel(intrinsics, distorted
                                               ? geometry::Distortion::RadialTangential(distortion)
                                               : geometry::Distortion());
}

geometry::Pose GazeboCamera::X_LOptical() const {
  // Optical x = -y, y = -z, z = +x of Gazebo's camera frame: rpy (-pi/2, 0, -pi/2), exactly.
  Eigen::Matrix3d R;
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return X_LS * geometry::MakePose(R, Eigen::Vector3d::Zero());
}

const GazeboCamera* UrdfModel::FindCamera(const std::string& sensor_name) const {
  for (const GazeboCamera& c : cameras) {
    if (c.name == sensor_name) return &c;
  }
  return nullptr;
}

std::optional<fs::path> ResolveMeshUri(const std::string& uri, const fs::path& base_dir,
                                       const UrdfOptions& options,
                                       std::vector<std::string>* searched) {
  std::vector<fs::path> candidates;
  const std::string package_scheme = "package://";
  const std::string file_scheme = "file://";
  if (uri.rfind(package_scheme, 0) == 0) {
    const std::string rest = uri.substr(package_scheme.size());
    const size_t slash = rest.find('/');
    const std::string package = rest.substr(0, slash);
    const std::string inside = slash == std::string::npos ? "" : rest.substr(slash + 1);
    if (const auto it = options.packages.find(package); it != options.packages.end()) {
      candidates.push_back(it->second / inside);
    }
    std::vector<fs::path> dirs;
    for (const char* variable : {"SACCADE_PACKAGE_PATH", "ROS_PACKAGE_PATH"}) {
      for (const std::string& dir : SplitPath(variable)) dirs.emplace_back(dir);
    }
    for (fs::path dir = fs::absolute(base_dir).lexically_normal();; dir = dir.parent_path()) {
      dirs.push_back(dir);
      if (dir == dir.parent_path()) break;
    }
    for (const fs::path& dir : dirs) {
      if (dir.filename() == package) candidates.push_back(dir / inside);
      candidates.push_back(dir / package / inside);
    }
  } else if (uri.rfind(file_scheme, 0) == 0) {
    candidates.emplace_back(uri.substr(file_scheme.size()));
  } else {
    const fs::path path(uri);
    candidates.push_back(path.is_absolute() ? path : base_dir / path);
  }
  for (const fs::path& candidate : candidates) {
    std::error_code error;
    if (fs::is_regular_file(candidate, error)) return candidate.lexically_normal();
    if (searched) searched->push_back(candidate.string());
  }
  return std::nullopt;
}

UrdfModel ParseUrdf(const std::string& xml, const std::string& source, const fs::path& base_dir,
                    const UrdfOptions& options) {
  TiXmlDocument document;
  document.Parse(xml.c_str(), nullptr, TIXML_ENCODING_UTF8);
  if (document.Error()) {
    throw FileError(
        source, document.ErrorRow(), "xml",
        fmt::format("{}; expected a URDF file (XML with a <robot> root)", document.ErrorDesc()));
  }
  const TiXmlElement* robot = document.RootElement();
  if (robot == nullptr || robot->ValueStr() != "robot") {
    throw FileError(source, robot ? robot->Row() : 0, "robot",
                    fmt::format("the root element is <{}>; expected <robot> (a URDF file)",
                                robot ? robot->ValueStr() : std::string()));
  }
  const ElementLines lines = ScanElements(*robot);
  RefuseCycles(source, lines);

  urdf::ModelInterfaceSharedPtr model;
  {
    const std::lock_guard lock(console_mutex);
    CapturedConsole console;
    try {
      model = urdf::parseURDF(xml);
    } catch (const std::exception& e) {
      throw FileError(source, robot->Row(), "robot", fmt::format("urdfdom: {}", e.what()));
    }
    if (!model) ThrowUrdfdomError(source, lines, console.errors());
  }

  std::vector<JointSpec> joints;
  for (const std::string& name : lines.joints) {
    const urdf::JointConstSharedPtr joint = model->getJoint(name);
    if (joint) joints.push_back(ToJointSpec(*joint, source, lines.Line(name)));
  }
  UrdfModel result{model->getName(),
                   KinematicTree::Build(lines.links, joints, source, lines.link_lines),
                   {},
                   {},
                   xml,
                   source};
  result.visuals = ReadVisuals(*model, result.tree, lines, source, base_dir, options);
  GazeboReader(source, result.tree).Read(*robot, &result.cameras);
  return result;
}

UrdfModel LoadUrdfFile(const fs::path& path, const UrdfOptions& options) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw FileError(path.string(), 0, "urdf", "cannot open the file");
  std::stringstream text;
  text << file.rdbuf();
  return ParseUrdf(text.str(), path.string(), path.parent_path(), options);
}

}  // namespace saccade::head
