// Scene files: YAML to a validated Scene (the format is documented at the top of
// scenes/portraits.yaml). Every error is a FileError "file:line: key.path: what", including
// those of the files a scene refers to (their own message follows, naming their path).

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <system_error>
#include <utility>

#include "core/internal_yaml.h"
#include "internal_assets.h"
#include "internal_robot_body.h"
#include "internal_scene_entries.h"
#include "saccade/core/error.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/scene/limits.h"
#include "saccade/scene/scene.h"

namespace saccade::scene {
namespace {

namespace fs = std::filesystem;
using saccade::internal::Entry;
using namespace internal_reader;  // NOLINT: this file's own helpers

class SceneReader {
 public:
  SceneReader(std::string source, fs::path base_dir, LoadOptions options)
      : source_(std::move(source)), base_dir_(std::move(base_dir)), options_(std::move(options)) {}

  Scene Read(const YAML::Node& root) {
    const Entry top(root, "", &source_, 1);
    if (!root.IsMap()) {
      top.Fail(
          "expected a scene (a map with background, lights, ground, objects, robot, cameras), "
          "got " +
          top.Describe());
    }
    top.ExpectMap({"background", "lights", "ground", "objects", "robot", "cameras"}, "a scene");

    Eigen::Vector3f background(0.62f, 0.72f, 0.82f);
    if (const auto e = top.Find("background")) background = Rgb(ToEigen(e->AsColor(false)));

    std::vector<Light> lights;
    if (const auto e = top.Find("lights")) {
      for (const Entry& item : e->AsSequence("lights")) lights.push_back(ReadLight(item));
    } else {
      lights = DefaultLights();
    }

    Ground ground;
    if (const auto e = top.Find("ground")) ground = ReadGround(*e);

    std::vector<Object> objects;
    std::vector<std::optional<Entry>> id_entries;
    std::map<std::string, std::string> object_names;  // name -> key path
    if (const auto e = top.Find("objects")) {
      const std::vector<Entry> items = e->AsSequence("objects");
      if (items.size() > static_cast<std::size_t>(kMaxObjects)) {
        e->Fail(fmt::format("{} objects, more than the {} a scene may hold", items.size(),
                            kMaxObjects));
      }
      for (const Entry& item : items) {
        std::optional<Entry> id_entry;
        objects.push_back(ReadObject(item, &id_entry, object_names));
        id_entries.push_back(id_entry);
      }
    }

    std::vector<CameraSpec> cameras;
    std::map<std::string, std::string> camera_names;  // name -> key path
    std::optional<Robot> robot;
    std::optional<Entry> robot_id_entry;
    if (!options_.head.empty() && !top.Find("robot")) {
      top.Fail(
          fmt::format("the head '{}' replaces the scene's robot head, but this scene has no "
                      "robot: add one (robot: {{head: FILE}})",
                      options_.head.string()));
    }
    if (const auto e = top.Find("robot")) {
      robot = ReadRobot(*e, &cameras, &robot_id_entry);
      for (const CameraSpec& camera : cameras) {
        camera_names.emplace(camera.name, "the robot's " + camera.name + " eye camera");
        const auto calibration =
            e->Find("cameras") ? e->Find("cameras")->Find(camera.name.c_str()) : std::nullopt;
        CheckImageBudget(camera, calibration ? *calibration : e->Get("head"));
      }
    }
    if (const auto e = top.Find("cameras")) {
      const std::vector<Entry> items = e->AsSequence("cameras");
      if (items.size() + cameras.size() > static_cast<std::size_t>(kMaxCameras)) {
        e->Fail(fmt::format("{} cameras, more than the {} a scene may hold",
                            items.size() + cameras.size(), kMaxCameras));
      }
      for (const Entry& item : items) {
        cameras.push_back(ReadWorldCamera(item, camera_names));
        CheckImageBudget(cameras.back(), item.Get("calibration"));
      }
    }
    int64_t pixels = 0;
    for (const CameraSpec& camera : cameras) {
      pixels += int64_t{camera.model.intrinsics().width()} * camera.model.intrinsics().height();
    }
    if (pixels > kMaxScenePixels) {
      top.Fail(
          fmt::format("the cameras have {:.1f} Mpx together, more than the {:.0f} Mpx that "
                      "saccade renders at once (scene/limits.h)",
                      pixels * 1e-6, kMaxScenePixels * 1e-6));
    }

    AssignIds(objects, id_entries, robot ? &*robot : nullptr, robot_id_entry);
    try {
      return Scene(background, std::move(lights), std::move(ground), std::move(objects),
                   std::move(cameras), std::move(robot));
    } catch (const InvalidArgument& error) {
      // Everything was checked above with its line; this is a safety net naming the file.
      throw FileError(source_, 0, "", error.what());
    }
  }

 private:
  // --- files --------------------------------------------------------------------------
  // A path relative to the scene's folder, to an existing regular file; canonical.
  fs::path ResolveFile(const Entry& e, const char* what) const {
    const std::string text = e.AsNonEmptyString();
    if (text.find('\0') != std::string::npos) e.Fail("a path cannot contain a NUL character");
    fs::path path(text);
    if (path.is_relative()) path = base_dir_ / path;
    path = path.lexically_normal();
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (!fs::exists(status)) {
      e.Fail(fmt::format("{} not found: '{}' (looked for {})", what, text, path.string()));
    }
    if (!fs::is_regular_file(status)) {
      e.Fail(fmt::format("{} '{}' is not a regular file ({})", what, text, path.string()));
    }
    // /proc/kcore and the like claim to be huge regular files: never hand them to a parser.
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec || size > kMaxFileBytes) {
      e.Fail(fmt::format("{} '{}' is not readable or larger than {} bytes ({})", what, text,
                         kMaxFileBytes, path.string()));
    }
    const fs::path canonical = fs::canonical(path, ec);
    return ec ? path : canonical;
  }

  std::shared_ptr<const Texture> ReadTexture(const Entry& e, const char* what) {
    const fs::path path = ResolveFile(e, what);
    try {
      return internal::LoadTexture(path, cache_);
    } catch (const Error& error) {
      e.Fail(fmt::format("cannot read {} '{}': {}", what, e.AsString(), error.what()));
    }
  }

  // --- lights and ground --------------------------------------------------------------
  static std::vector<Light> DefaultLights() {
    Light ambient;
    ambient.type = Light::Type::kAmbient;
    ambient.intensity = 0.35f;
    Light sun;
    sun.type = Light::Type::kDirectional;
    sun.intensity = 0.8f;
    sun.direction_W = Eigen::Vector3d(-0.4, -0.3, -1.0).normalized();
    return {ambient, sun};
  }

  Light ReadLight(const Entry& e) {
    if (!e.IsMap()) e.Fail("expected a light (a map with type, ...), got " + e.Describe());
    const Entry type_entry = e.Get("type");
    const std::string type = type_entry.AsString();
    Light light;
    if (type == "ambient") {
      light.type = Light::Type::kAmbient;
      e.ExpectMap({"type", "color", "intensity"}, "an ambient light");
    } else if (type == "directional") {
      light.type = Light::Type::kDirectional;
      e.ExpectMap({"type", "color", "intensity", "direction"}, "a directional light");
      const Entry direction = e.Get("direction");
      const Eigen::Vector3d d = ToEigen(direction.AsVector3());
      if (!(d.norm() > 0.0)) direction.Fail("expected a non-zero direction, got [0, 0, 0]");
      light.direction_W = d.normalized();
    } else if (type == "point") {
      light.type = Light::Type::kPoint;
      e.ExpectMap({"type", "color", "intensity", "position", "attenuation"}, "a point light");
      light.position_W = ToEigen(e.Get("position").AsVector3());
      if (const auto a = e.Find("attenuation")) light.attenuation = a->AsNonNegative();
    } else {
      type_entry.Fail("expected 'ambient', 'directional' or 'point', got " + type_entry.Describe());
    }
    if (const auto c = e.Find("color")) light.color = Rgb(ToEigen(c->AsColor(false)));
    if (const auto i = e.Find("intensity"))
      light.intensity = static_cast<float>(i->AsNonNegative());
    return light;
  }

  Ground ReadGround(const Entry& e) {
    e.ExpectMap({"enabled", "size", "pattern", "cell", "line_width", "color", "color2"},
                "a ground {size, pattern, cell, ...}");
    Ground g;
    if (const auto x = e.Find("enabled")) g.enabled = x->AsBool();
    if (const auto x = e.Find("size")) g.size = x->AsPositive();
    if (const auto x = e.Find("pattern")) {
      const std::string pattern = x->AsString();
      if (pattern == "plain") {
        g.pattern = Ground::Pattern::kPlain;
      } else if (pattern == "grid") {
        g.pattern = Ground::Pattern::kGrid;
      } else if (pattern == "checker") {
        g.pattern = Ground::Pattern::kChecker;
      } else {
        x->Fail("expected 'plain', 'grid' or 'checker', got " + x->Describe());
      }
    }
    if (const auto x = e.Find("cell")) g.cell = x->AsPositive();
    if (const auto x = e.Find("line_width")) g.line_width = x->AsPositive();
    if (!(g.line_width < g.cell)) {
      (e.Find("line_width") ? *e.Find("line_width") : e.Get("cell"))
          .Fail(fmt::format("expected line_width < cell, got line_width {} m and cell {} m",
                            g.line_width, g.cell));
    }
    if (const auto x = e.Find("color")) g.color = Rgb(ToEigen(x->AsColor(false)));
    if (const auto x = e.Find("color2")) g.color2 = Rgb(ToEigen(x->AsColor(false)));
    return g;
  }

  // --- objects ------------------------------------------------------------------------
  std::shared_ptr<const Model> Primitive(const std::string& kind, const Eigen::Vector4f& color) {
    const std::string key =
        fmt::format("{} {} {} {} {}", kind, color[0], color[1], color[2], color[3]);
    auto& model = primitives_[key];
    if (model == nullptr) {
      model = kind == "box"      ? MakeBox(color)
              : kind == "sphere" ? MakeSphere(color)
                                 : MakePlane(color);
    }
    return model;
  }

  Object ReadObject(const Entry& e, std::optional<Entry>* id_entry,
                    std::map<std::string, std::string>& names) {
    if (!e.IsMap()) e.Fail("expected an object (a map with name, kind, ...), got " + e.Describe());
    const Entry kind_entry = e.Get("kind");
    const std::string kind = kind_entry.AsString();
    std::vector<std::string> keys = {"name", "kind", "id", "pose", "scale", "motion"};
    if (kind == "model") {
      keys.insert(keys.end(), {"file", "unit_scale", "texture"});
    } else if (kind == "picture") {
      keys.insert(keys.end(), {"image", "height"});
    } else if (kind == "box" || kind == "plane") {
      keys.insert(keys.end(), {"size", "color"});
    } else if (kind == "sphere") {
      keys.insert(keys.end(), {"radius", "color"});
    } else {
      kind_entry.Fail("expected 'model', 'picture', 'box', 'sphere' or 'plane', got " +
                      kind_entry.Describe());
    }
    const std::string what = "a " + kind + " object";
    e.ExpectMap(keys, what.c_str());

    Object object;
    const Entry name_entry = e.Get("name");
    object.name = name_entry.AsNonEmptyString();
    if (const auto [it, inserted] = names.emplace(object.name, e.path()); !inserted) {
      name_entry.Fail(fmt::format("duplicate object name '{}' (also {})", object.name, it->second));
    }
    if (const auto id = e.Find("id")) {
      object.id = static_cast<uint32_t>(id->AsInteger(1, kMaxId));
      *id_entry = id;
    }
    Eigen::Vector3d scale = Eigen::Vector3d::Ones();
    if (const auto s = e.Find("scale")) scale = ReadPositiveSizes(*s, 3, "[sx, sy, sz]");

    if (kind == "model") {
      std::shared_ptr<const Texture> texture;
      if (const auto t = e.Find("texture")) texture = ReadTexture(*t, "texture");
      const Entry file = e.Get("file");
      const fs::path path = ResolveFile(file, "model file");
      try {
        object.model = internal::LoadModelFile(path, texture, cache_);
      } catch (const Error& error) {
        file.Fail(fmt::format("cannot load model '{}': {}", file.AsString(), error.what()));
      }
      // The unit scale goes to the object, so that one loaded model serves every scale.
      if (const auto u = e.Find("unit_scale")) scale *= u->AsPositive();
    } else if (kind == "picture") {
      const auto texture = ReadTexture(e.Get("image"), "image");
      const Entry height = e.Get("height");
      const double metres = height.AsPositive();
      // Its width follows from the image's aspect (a 1 x 100000 image is 100000 times wider).
      const double width = metres * texture->image.width() / texture->image.height();
      if (!(metres <= kMaxPictureSide && width <= kMaxPictureSide)) {
        height.Fail(fmt::format(
            "a picture of {:g} m x {:g} m (width from the image's {} x {} pixels); at most {:g} m "
            "a side",
            width, metres, texture->image.width(), texture->image.height(), kMaxPictureSide));
      }
      const std::string key = fmt::format("{}\n{}", texture->source, metres);
      auto& model = pictures_[key];
      if (model == nullptr) model = MakePicture(texture, metres);
      object.model = model;
    } else {
      Eigen::Vector4f color = kDefaultPrimitiveColor;
      if (const auto c = e.Find("color")) color = ToEigen(c->AsColor(true));
      object.model = Primitive(kind, color);
      if (kind == "box") {
        scale = scale.cwiseProduct(ReadPositiveSizes(e.Get("size"), 3, "[x, y, z]"));
      } else if (kind == "plane") {
        scale = scale.cwiseProduct(ReadPositiveSizes(e.Get("size"), 2, "[x, y]"));
      } else {
        scale *= 2.0 * e.Get("radius").AsPositive();  // the unit sphere has radius 0.5
      }
    }
    // Products of valid scales can still overflow or underflow.
    if (!(scale.allFinite() && scale.minCoeff() > 0.0)) {
      e.Fail(
          "the object's total scale (scale x size x unit_scale) is not a positive finite number");
    }
    object.scale = scale;

    const auto pose = e.Find("pose");
    const geometry::Pose X_WO = pose ? ReadPose(*pose) : geometry::Pose::Identity();
    if (const auto motion = e.Find("motion")) {
      object.motion = ReadMotion(*motion, X_WO, pose);
    } else {
      object.motion = Motion::Static(X_WO);
    }
    return object;
  }

  Motion ReadMotion(const Entry& e, const geometry::Pose& X_WO, const std::optional<Entry>& pose) {
    if (!e.IsMap()) e.Fail("expected a motion (a map with type, ...), got " + e.Describe());
    const Entry type_entry = e.Get("type");
    const std::string type = type_entry.AsString();
    if (type == "waypoints") {
      e.ExpectMap({"type", "waypoints", "loop"}, "a waypoint motion");
      if (pose) {
        pose->Fail(
            "give either 'pose' or a waypoint motion, not both (the waypoints place the object)");
      }
      const Entry list = e.Get("waypoints");
      std::vector<Motion::Waypoint> waypoints;
      for (const Entry& item : list.AsSequence("waypoints {time, position, rpy_deg}")) {
        item.ExpectMap({"time", "position", "rpy", "rpy_deg"},
                       "a waypoint {time, position, rpy_deg}");
        const Entry time = item.Get("time");
        Motion::Waypoint waypoint;
        waypoint.time = time.AsNonNegative();
        if (!waypoints.empty() && !(waypoint.time > waypoints.back().time)) {
          time.Fail(fmt::format("expected a time after the previous waypoint's ({} s), got {} s",
                                waypoints.back().time, waypoint.time));
        }
        waypoint.pose = PoseFrom(
            ToEigen(item.Get("position").AsVector3()),
            FindAngles(item, "rpy", "[roll, pitch, yaw]").value_or(Eigen::Vector3d::Zero()));
        waypoints.push_back(waypoint);
      }
      if (waypoints.empty()) list.Fail("expected at least one waypoint, got an empty list");
      bool loop = false;
      if (const auto l = e.Find("loop")) {
        loop = l->AsBool();
        if (loop && !(waypoints.back().time > 0.0)) {
          l->Fail("a loop needs the last waypoint's time (the period) > 0");
        }
      }
      try {
        return Motion::Waypoints(std::move(waypoints), loop);
      } catch (const InvalidArgument& error) {
        e.Fail(error.what());
      }
    }
    if (type == "constant_velocity") {
      e.ExpectMap({"type", "linear", "angular", "angular_deg"}, "a constant-velocity motion");
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      if (const auto l = e.Find("linear")) v = ToEigen(l->AsVector3("[vx, vy, vz] (m/s)"));
      const Eigen::Vector3d w = FindAngles(e, "angular", "[wx, wy, wz] (about world axes)")
                                    .value_or(Eigen::Vector3d::Zero());
      try {
        return Motion::ConstantVelocity(X_WO, v, w);
      } catch (const InvalidArgument& error) {
        e.Fail(error.what());
      }
    }
    type_entry.Fail("expected 'waypoints' or 'constant_velocity', got " + type_entry.Describe());
  }

  // --- cameras ------------------------------------------------------------------------

  // A calibration: a file name, {file, width, height}, or inline intrinsics.
  geometry::CameraModel ReadCalibration(const Entry& e) {
    if (e.IsScalar()) return ReadCalibrationFile(e, std::nullopt);
    if (!e.IsMap()) {
      e.Fail("expected a calibration file name or a map of intrinsics, got " + e.Describe());
    }
    if (const auto file = e.Find("file")) {
      e.ExpectMap({"file", "width", "height"}, "a calibration {file, width, height}");
      std::optional<geometry::ImageSize> size;
      if (e.Has("width") || e.Has("height")) {
        size = geometry::ImageSize{static_cast<int>(e.Get("width").AsInteger(1, 1'000'000)),
                                   static_cast<int>(e.Get("height").AsInteger(1, 1'000'000))};
      }
      return ReadCalibrationFile(*file, size);
    }
    e.ExpectMap({"width", "height", "fx", "fy", "focal_length_mm", "pixel_size_um", "cx", "cy",
                 "skew", "distortion"},
                "intrinsics {width, height, fx, fy, cx, cy, skew, distortion}");
    const int width = static_cast<int>(e.Get("width").AsInteger(1, 1'000'000));
    const int height = static_cast<int>(e.Get("height").AsInteger(1, 1'000'000));
    double fx = 0.0, fy = 0.0;
    if (e.Has("focal_length_mm") || e.Has("pixel_size_um")) {
      for (const char* key : {"fx", "fy"}) {
        if (const auto x = e.Find(key)) {
          x->Fail("give either fx and fy, or focal_length_mm and pixel_size_um, not both");
        }
      }
      fx = fy =
          e.Get("focal_length_mm").AsPositive() / (e.Get("pixel_size_um").AsPositive() * 1e-3);
    } else {
      fx = e.Get("fx").AsPositive();
      fy = e.Get("fy").AsPositive();
    }
    const auto cx = e.Find("cx");
    const auto cy = e.Find("cy");
    const auto skew = e.Find("skew");
    geometry::Distortion distortion;
    if (const auto d = e.Find("distortion")) {
      d->ExpectMap({"model", "coefficients"}, "a distortion {model, coefficients}");
      const Entry model_entry = d->Get("model");
      const std::string name = model_entry.AsString();
      geometry::DistortionModel model = geometry::DistortionModel::kNone;
      if (name == "radtan") {
        model = geometry::DistortionModel::kRadialTangential;
      } else if (name == "fisheye") {
        model = geometry::DistortionModel::kFisheye;
      } else if (name != "none") {
        model_entry.Fail("expected 'none', 'radtan' or 'fisheye', got " + model_entry.Describe());
      }
      std::vector<double> coefficients;
      const auto c = d->Find("coefficients");
      if (c) {
        for (const Entry& k : c->AsSequence("coefficients")) coefficients.push_back(k.AsDouble());
      }
      try {
        distortion = geometry::Distortion::FromCoefficients(model, coefficients);
      } catch (const Error& error) {
        (c ? *c : model_entry).Fail(error.what());
      }
    }
    try {
      return geometry::CameraModel(
          geometry::Intrinsics(width, height, fx, fy, cx ? cx->AsDouble() : 0.5 * (width - 1),
                               cy ? cy->AsDouble() : 0.5 * (height - 1),
                               skew ? skew->AsDouble() : 0.0),
          distortion);
    } catch (const InvalidArgument& error) {
      e.Fail(error.what());
    }
  }

  geometry::CameraModel ReadCalibrationFile(const Entry& e,
                                            std::optional<geometry::ImageSize> size) const {
    const fs::path path = ResolveFile(e, "calibration file");
    try {
      return geometry::ReadCameraCalibration(path, size).model;
    } catch (const Error& error) {
      e.Fail(fmt::format("cannot read calibration '{}': {}", e.AsString(), error.what()));
    }
  }

  CameraSpec ReadWorldCamera(const Entry& e, std::map<std::string, std::string>& names) {
    e.ExpectMap({"name", "calibration", "pose", "look_at", "clip", "sensor", "lens"},
                "a camera {name, calibration, pose | look_at, clip, sensor, lens}");
    const Entry name_entry = e.Get("name");
    const std::string name = name_entry.AsNonEmptyString();
    CheckCameraName(name_entry, name, names);
    const auto pose = e.Find("pose");
    const auto look_at = e.Find("look_at");
    if (pose && look_at) look_at->Fail("give either 'pose' or 'look_at', not both");
    if (!pose && !look_at) e.Fail("missing the camera's placement: give 'pose' or 'look_at'");
    CameraSpec camera{name,
                      ReadCalibration(e.Get("calibration")),
                      CameraMount::kWorld,
                      pose ? ReadPose(*pose) : ReadLookAt(*look_at),
                      geometry::ClipPlanes{kDefaultNear, kDefaultFar},
                      SensorSpec{}};
    if (const auto clip = e.Find("clip")) camera.clip = ReadClip(*clip);
    if (const auto sensor = e.Find("sensor")) camera.sensor = ReadSensor(*sensor);
    if (const auto lens = e.Find("lens")) camera.lens = ReadLens(*lens);
    return camera;
  }

  // --- robot --------------------------------------------------------------------------
  Robot ReadRobot(const Entry& e, std::vector<CameraSpec>* cameras,
                  std::optional<Entry>* id_entry) {
    e.ExpectMap({"head", "id", "pose", "joints", "joints_deg", "visible", "cameras"},
                "a robot {head, joints_deg, pose, visible, cameras}");
    const Entry head_entry = e.Get("head");
    const bool replaced = !options_.head.empty();  // LoadOptions::head: the scene's is not used
    const fs::path head_path =
        replaced ? options_.head : ResolveFile(head_entry, "head description");
    std::optional<head::HeadModel> model;
    try {
      model.emplace(head::HeadModel::FromFile(head_path));
    } catch (const Error& error) {
      if (replaced) throw;  // names the head file, which is not this scene's
      head_entry.Fail(fmt::format("cannot load head description '{}': {}", head_entry.AsString(),
                                  error.what()));
    }
    if (const auto pose = e.Find("pose")) {
      const geometry::Pose X_WB = ReadPose(*pose);
      if (!replaced) model.emplace(model->WithPose(X_WB));
    }

    geometry::ClipPlanes clips[2];
    SensorSpec sensors[2];
    LensSpec lenses[2];
    for (int i = 0; i < 2; ++i) {
      const auto& clip = model->camera(i).clip;
      clips[i] = clip ? geometry::ClipPlanes{clip->first, clip->second}
                      : geometry::ClipPlanes{kDefaultNear, kDefaultFar};
    }
    if (const auto c = e.Find("cameras")) {
      c->ExpectMap({"left", "right"}, "the eye cameras {left, right}");
      for (int i = 0; i < 2; ++i) {
        const auto camera = c->Find(i == 0 ? "left" : "right");
        if (!camera) continue;
        camera->ExpectMap({"calibration", "clip", "sensor", "lens"},
                          "an eye camera {calibration, clip, sensor, lens}");
        if (const auto calibration = camera->Find("calibration")) {
          const geometry::CameraModel eye = ReadCalibration(*calibration);
          if (!replaced) model.emplace(model->WithCamera(i, eye));
        }
        if (const auto clip = camera->Find("clip")) clips[i] = ReadClip(*clip);
        if (const auto sensor = camera->Find("sensor")) sensors[i] = ReadSensor(*sensor);
        if (const auto lens = camera->Find("lens")) lenses[i] = ReadLens(*lens);
      }
    }
    Robot robot{*model, model->Home(), true, {}, 0};
    if (!replaced) ReadInitialJoints(e, &robot);
    if (const auto v = e.Find("visible")) robot.visible = v->AsBool();
    if (const auto id = e.Find("id")) {
      robot.id = static_cast<uint32_t>(id->AsInteger(1, kMaxId));
      *id_entry = id;
    }
    try {
      robot.parts = robot.head.appendix_a() ? internal::BuildRobotBody(robot.head)
                                            : internal::BuildUrdfVisuals(robot.head, cache_);
    } catch (const Error& error) {
      head_entry.Fail(fmt::format("cannot build the robot's body: {}", error.what()));
    }
    cameras->push_back(CameraSpec{"left", robot.head.camera(0).model, CameraMount::kLeftEye,
                                  geometry::Pose::Identity(), clips[0], sensors[0], lenses[0]});
    cameras->push_back(CameraSpec{"right", robot.head.camera(1).model, CameraMount::kRightEye,
                                  geometry::Pose::Identity(), clips[1], sensors[1], lenses[1]});
    return robot;
  }

  // `joints` (radians) or `joints_deg`: a list in the head's joint order, or a map of joint
  // name to value where joints left out stay at home.
  void ReadInitialJoints(const Entry& e, Robot* robot) {
    const auto rad = e.Find("joints");
    const auto deg = e.Find("joints_deg");
    if (rad && deg) deg->Fail("give either 'joints' (radians) or 'joints_deg', not both");
    if (!rad && !deg) return;
    const Entry& joints = rad ? *rad : *deg;
    const double k = deg ? kDegToRad : 1.0;
    const head::HeadModel& head = robot->head;
    head::JointState q = head.Home();
    if (joints.IsMap()) {
      for (const auto& item : joints.node()) {
        const std::string name = item.first.as<std::string>();
        const Entry value = joints.Get(name.c_str());
        const int i = head.FindJoint(name);
        if (i < 0) {
          value.Fail(fmt::format("the head has no joint '{}'; its joints are: {}", name,
                                 head::ListNames(*head.joint_names())));
        }
        q[i] = value.AsDouble() * k;
      }
    } else {
      const std::string names = "[" + head::ListNames(*head.joint_names()) + "]";
      const std::vector<double> values = joints.AsDoubles(head.num_joints(), names.c_str());
      for (int i = 0; i < head.num_joints(); ++i) q[i] = values[i] * k;
    }
    try {
      head.CheckLimits(q.values());
    } catch (const InvalidArgument& error) {
      joints.Fail(error.what());
    }
    robot->initial_joints = q;
  }

  // --- instance ids -------------------------------------------------------------------

  std::string source_;
  fs::path base_dir_;
  LoadOptions options_;
  internal::AssetCache cache_;
  std::map<std::string, std::shared_ptr<const Model>> primitives_;
  std::map<std::string, std::shared_ptr<const Model>> pictures_;
};

}  // namespace

Scene Scene::Load(const std::filesystem::path& path, const LoadOptions& options) {
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw FileError(name, 0, "", "scene file not found");
  if (!fs::is_regular_file(path, ec))
    throw FileError(name, 0, "", "the scene is not a regular file");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw FileError(name, 0, "", "cannot open the scene file");
  std::stringstream text;
  text << stream.rdbuf();
  if (stream.bad()) throw FileError(name, 0, "", "cannot read the scene file");
  fs::path base_dir = path.parent_path();
  if (base_dir.empty()) base_dir = ".";
  return FromYamlString(text.str(), name, base_dir, options);
}

Scene Scene::FromYamlString(const std::string& text, const std::string& source,
                            const std::filesystem::path& base_dir, const LoadOptions& options) {
  const YAML::Node root = saccade::internal::ParseYaml(text, source);
  try {
    return SceneReader(source, base_dir, options).Read(root);
  } catch (const FileError&) {
    throw;
  } catch (const YAML::Exception& error) {
    // Every access is checked; never let a YAML exception escape all the same.
    throw FileError(source, error.mark.is_null() ? 0 : error.mark.line + 1, "", error.msg);
  }
}

}  // namespace saccade::scene
