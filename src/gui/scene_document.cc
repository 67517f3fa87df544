#include <fmt/format.h>

#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "gui/internal_scene_document.h"
#include "saccade/core/error.h"
#include "saccade/geometry/json.h"
#include "saccade/head/json.h"

namespace saccade::gui::internal {
namespace {

using nlohmann::json;

json Vec(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }
json Vec(const Eigen::Vector4f& v) { return {v.x(), v.y(), v.z(), v.w()}; }

/// A texture as PNG bytes.
std::string EncodePng(const Image& image) {
  cv::Mat bgr;
  uint8_t* data = const_cast<uint8_t*>(image.data());
  if (image.format() == PixelFormat::kRgb8) {
    cv::cvtColor(cv::Mat(image.height(), image.width(), CV_8UC3, data), bgr, cv::COLOR_RGB2BGR);
  } else if (image.format() == PixelFormat::kRgba8) {
    cv::cvtColor(cv::Mat(image.height(), image.width(), CV_8UC4, data), bgr, cv::COLOR_RGBA2BGRA);
  } else if (image.format() == PixelFormat::kGray8) {
    bgr = cv::Mat(image.height(), image.width(), CV_8UC1, data).clone();
  } else {
    throw Error(std::string("gui: cannot send a texture of format ") + ToString(image.format()));
  }
  std::vector<uint8_t> png;
  cv::imencode(".png", bgr, png);
  return std::string(png.begin(), png.end());
}

template <typename T>
void Append(std::string& out, const T* data, std::size_t count) {
  out.append(reinterpret_cast<const char*>(data), count * sizeof(T));
}

/// The meshes of a model, as /api/models/N.bin (docs/gui-protocol.md).
std::string ModelBinary(const scene::Model& model) {
  std::string out;
  for (const scene::Mesh& mesh : model.meshes) {
    for (const Eigen::Vector3f& p : mesh.positions) Append(out, p.data(), 3);
    for (const Eigen::Vector3f& n : mesh.normals) Append(out, n.data(), 3);
    for (const Eigen::Vector2f& uv : mesh.uvs) Append(out, uv.data(), 2);
    Append(out, mesh.indices.data(), mesh.indices.size());
  }
  return out;
}

}  // namespace

json FramesJson(const head::HeadModel& head, const head::JointState& joints) {
  std::vector<geometry::Pose> X_WL;
  head.ForwardKinematics(head.Posture(joints), &X_WL);
  json links = json::object();
  for (int l = 0; l < head.tree().num_links(); ++l)
    links[head.tree().link_name(l)] = ToJson(X_WL[l]);
  const geometry::Pose left = head.CameraPose(0, X_WL);
  const geometry::Pose right = head.CameraPose(1, X_WL);
  geometry::Pose X_WC = head.X_WB();
  X_WC.translation() = 0.5 * (left.translation() + right.translation());
  return {{"X_WB", ToJson(X_WL[head.tree().root()])},
          {"X_WC", ToJson(X_WC)},
          {"links", links},
          {"left", ToJson(left)},
          {"right", ToJson(right)}};
}

json MovingObjectsJson(const scene::Scene& scene, double t) {
  json objects = json::array();
  for (const scene::Object& o : scene.objects()) {
    if (!o.motion.IsStatic())
      objects.push_back({{"name", o.name}, {"X_WO", ToJson(o.motion.PoseAt(t))}});
  }
  return objects;
}

namespace {

// The scene's models, each once, as the renderer has them: their meshes and textures put on
// the server as documents, their descriptions gathered for the scene document's "models".
class ModelCatalog {
 public:
  explicit ModelCatalog(server::GuiServer& server) : server_(server) {}

  /// The model's index in "models" (-1 for none), adding it the first time.
  int Add(const std::shared_ptr<const scene::Model>& model) {
    if (!model) return -1;
    if (const auto it = index_.find(model.get()); it != index_.end()) return it->second;
    const int index = static_cast<int>(models_.size());
    index_[model.get()] = index;
    json materials = json::array();
    for (const scene::Material& m : model->materials) {
      materials.push_back({{"base_color", Vec(m.base_color)},
                           {"texture", m.texture ? json(Texture(*m.texture)) : json(nullptr)},
                           {"specular", m.specular},
                           {"shininess", m.shininess}});
    }
    json meshes = json::array();
    for (const scene::Mesh& mesh : model->meshes) {
      meshes.push_back({{"vertices", mesh.positions.size()},
                        {"indices", mesh.indices.size()},
                        {"uvs", !mesh.uvs.empty()},
                        {"material", mesh.material}});
    }
    const std::string url = fmt::format("/api/models/{}.bin", index);
    server_.SetDocument(url, "application/octet-stream", ModelBinary(*model));
    models_.push_back(
        {{"source", model->source},
         {"url", url},
         {"bounds",
          {Vec(Eigen::Vector3f(model->bounds.min())), Vec(Eigen::Vector3f(model->bounds.max()))}},
         {"materials", materials},
         {"meshes", meshes}});
    return index;
  }

  const json& models() const { return models_; }

 private:
  // The texture's URL, putting it on the server the first time.
  std::string Texture(const scene::Texture& texture) {
    auto [it, added] = texture_index_.emplace(&texture, static_cast<int>(texture_index_.size()));
    const std::string url = fmt::format("/api/textures/{}.png", it->second);
    if (added) server_.SetDocument(url, "image/png", EncodePng(texture.image));
    return url;
  }

  server::GuiServer& server_;
  std::map<const scene::Model*, int> index_;
  std::map<const scene::Texture*, int> texture_index_;
  json models_ = json::array();
};

json ObjectsJson(const scene::Scene& scene, ModelCatalog& models) {
  json objects = json::array();
  for (const scene::Object& o : scene.objects()) {
    objects.push_back({{"name", o.name},
                       {"id", o.id},
                       {"model", models.Add(o.model)},
                       {"scale", ToJson(o.scale)},
                       {"X_WO", ToJson(o.motion.PoseAt(0.0))},
                       {"moving", !o.motion.IsStatic()}});
  }
  return objects;
}

json RobotJson(const scene::Scene& scene, ModelCatalog& models) {
  if (!scene.robot()) return nullptr;
  const head::KinematicTree& tree = scene.robot()->head.tree();
  json links = json::array();
  links.push_back({{"name", tree.link_name(tree.root())}, {"parent", nullptr}, {"joint", nullptr}});
  for (const int j : tree.joint_order()) {
    const head::KinematicTree::Joint& joint = tree.joint(j);
    links.push_back({{"name", tree.link_name(joint.child)},
                     {"parent", tree.link_name(joint.parent)},
                     {"joint", joint.name}});
  }
  json parts = json::array();
  for (const scene::RobotPart& p : scene.robot()->parts) {
    parts.push_back({{"link", tree.link_name(p.link)},
                     {"model", models.Add(p.model)},
                     {"X_LinkPart", ToJson(p.X_LinkPart)},
                     {"scale", ToJson(p.scale)}});
  }
  return {{"visible", scene.robot()->visible}, {"links", links}, {"parts", parts}};
}

json HeadJson(const scene::Scene& scene) {
  json joints = json::array();
  json symmetric = json::array();
  if (!scene.robot()) return {{"name", ""}, {"joints", joints}, {"symmetric", symmetric}};
  const head::HeadModel& head = scene.robot()->head;
  const auto bound = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  for (int i = 0; i < head.num_joints(); ++i) {
    const head::KinematicTree::Joint& joint = head.tree().joint(head.tree().variable_joint(i));
    const head::JointLimits& l = head.joint(i).limits;
    joints.push_back({{"name", head.joint_name(i)},
                      {"type", head::ToString(joint.type)},
                      {"link", head.tree().link_name(joint.child)},
                      {"axis", ToJson<Eigen::Vector3d>(joint.axis)},
                      {"min", bound(l.min)},
                      {"max", bound(l.max)},
                      {"max_velocity", l.max_velocity},
                      {"driven", head.joint(i).driven}});
  }
  for (const head::FixationRule::Pair& p : head.fixation_rule().symmetric) {
    symmetric.push_back({head.joint_name(p.a), head.joint_name(p.b), p.sign});
  }
  return {{"name", head.name()}, {"joints", joints}, {"symmetric", symmetric}};
}

json LightsJson(const scene::Scene& scene) {
  json lights = json::array();
  for (const scene::Light& l : scene.lights()) {
    const char* type = l.type == scene::Light::Type::kAmbient       ? "ambient"
                       : l.type == scene::Light::Type::kDirectional ? "directional"
                                                                    : "point";
    lights.push_back({{"type", type},
                      {"color", Vec(l.color)},
                      {"intensity", l.intensity},
                      {"direction", ToJson(l.direction_W)},
                      {"position", ToJson(l.position_W)},
                      {"attenuation", l.attenuation}});
  }
  return lights;
}

json GroundJson(const scene::Ground& g) {
  const char* pattern = g.pattern == scene::Ground::Pattern::kPlain  ? "plain"
                        : g.pattern == scene::Ground::Pattern::kGrid ? "grid"
                                                                     : "checker";
  return {{"enabled", g.enabled},       {"size", g.size},
          {"pattern", pattern},         {"cell", g.cell},
          {"line_width", g.line_width}, {"color", Vec(g.color)},
          {"color2", Vec(g.color2)}};
}

json CamerasJson(const scene::Scene& scene) {
  json cameras = json::array();
  for (const scene::CameraSpec& c : scene.cameras()) {
    const char* eye = c.mount == scene::CameraMount::kLeftEye    ? "left"
                      : c.mount == scene::CameraMount::kRightEye ? "right"
                                                                 : "world";
    // The camera model's codec (geometry/json.h): width, height, K, distortion.
    json camera = ToJson(c.model);
    camera["name"] = c.name;
    camera["eye"] = eye;
    camera["X_WC"] = ToJson(c.X_WC);
    camera["near"] = c.clip.near;
    camera["far"] = c.clip.far;
    // What the `effects` switches optics and color change in its image.
    camera["optics"] = c.lens.Enabled();
    camera["color"] = c.sensor.color.Enabled();
    cameras.push_back(camera);
  }
  return cameras;
}

}  // namespace

json PublishScene(const scene::Scene& scene, const std::string& scene_name, const std::string& mode,
                  const json& commands, server::GuiServer& server) {
  ModelCatalog models(server);
  json objects = ObjectsJson(scene, models);
  json robot = RobotJson(scene, models);
  return {{"protocol", server::kProtocolName},
          {"version", server::kProtocolVersion},
          {"mode", mode},
          {"name", scene_name},
          {"time", 0.0},
          {"background", Vec(scene.background())},
          {"ground", GroundJson(scene.ground())},
          {"lights", LightsJson(scene)},
          {"models", models.models()},
          {"objects", objects},
          {"robot", robot},
          {"head", HeadJson(scene)},
          {"cameras", CamerasJson(scene)},
          {"commands", commands}};
}

}  // namespace saccade::gui::internal
