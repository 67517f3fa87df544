// The Scene value: validation of a world built in code, poses of cameras and objects.

#include "saccade/scene/scene.h"

#include <fmt/format.h>

#include <cmath>
#include <set>
#include <unordered_set>
#include <utility>

#include "internal_mesh.h"
#include "saccade/core/error.h"

namespace saccade::scene {
namespace {

// A rotation must be orthonormal to this to be a pose (rpy-built ones are, to ~1e-16).
constexpr double kRigidTolerance = 1e-9;

[[noreturn]] void Invalid(const std::string& what) { throw InvalidArgument("Scene: " + what); }

bool IsRigidPose(const geometry::Pose& X) {
  const Eigen::Matrix3d R = X.linear();
  return X.matrix().allFinite() &&
         (R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), kRigidTolerance) &&
         std::abs(R.determinant() - 1.0) <= kRigidTolerance;
}

bool IsColor(const Eigen::Vector3f& c) {
  return c.allFinite() && c.minCoeff() >= 0.0f && c.maxCoeff() <= 1.0f;
}

bool IsPositiveScale(const Eigen::Vector3d& s) { return s.allFinite() && s.minCoeff() > 0.0; }

void CheckModel(const std::shared_ptr<const Model>& model, const std::string& owner,
                std::unordered_set<const Model*>& checked) {
  if (model == nullptr) Invalid(owner + ": model is null");
  if (!checked.insert(model.get()).second) return;  // shared: checked once
  std::string error;
  if (!internal::IsValidModel(*model, &error)) {
    Invalid(fmt::format("{}: model '{}' {}", owner, model->source, error));
  }
}

void CheckLight(const Light& light, std::size_t i) {
  const std::string name = fmt::format("lights[{}]", i);
  if (!IsColor(light.color)) Invalid(name + ": colour must be RGB in [0, 1]");
  if (!std::isfinite(light.intensity) || light.intensity < 0.0f) {
    Invalid(fmt::format("{}: intensity must be finite and >= 0, got {}", name, light.intensity));
  }
  if (light.type == Light::Type::kDirectional &&
      !(light.direction_W.allFinite() && light.direction_W.norm() > 0.0)) {
    Invalid(name + ": direction must be a finite non-zero vector");
  }
  if (light.type == Light::Type::kPoint) {
    if (!light.position_W.allFinite()) Invalid(name + ": position must be finite");
    if (!std::isfinite(light.attenuation) || light.attenuation < 0.0) {
      Invalid(
          fmt::format("{}: attenuation must be finite and >= 0, got {}", name, light.attenuation));
    }
  }
}

void CheckGround(const Ground& g) {
  if (!std::isfinite(g.size) || g.size <= 0.0) {
    Invalid(fmt::format("ground: size must be positive, got {}", g.size));
  }
  if (!std::isfinite(g.cell) || g.cell <= 0.0) {
    Invalid(fmt::format("ground: cell must be positive, got {}", g.cell));
  }
  if (!std::isfinite(g.line_width) || g.line_width <= 0.0 || g.line_width >= g.cell) {
    Invalid(
        fmt::format("ground: line_width must be in (0, cell = {}), got {}", g.cell, g.line_width));
  }
  if (!IsColor(g.color) || !IsColor(g.color2)) Invalid("ground: colours must be RGB in [0, 1]");
}

}  // namespace

Scene::Scene(Eigen::Vector3f background, std::vector<Light> lights, Ground ground,
             std::vector<Object> objects, std::vector<CameraSpec> cameras,
             std::optional<Robot> robot)
    : background_(std::move(background)),
      lights_(std::move(lights)),
      ground_(std::move(ground)),
      objects_(std::move(objects)),
      cameras_(std::move(cameras)),
      robot_(std::move(robot)) {
  if (!IsColor(background_)) Invalid("background must be RGB in [0, 1]");
  for (std::size_t i = 0; i < lights_.size(); ++i) CheckLight(lights_[i], i);
  CheckGround(ground_);

  std::unordered_set<const Model*> checked;
  std::set<std::string> names;
  std::set<uint32_t> ids;
  const auto add_model = [this](const std::shared_ptr<const Model>& model) {
    for (const auto& known : models_) {
      if (known == model) return;
    }
    models_.push_back(model);
  };
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const Object& object = objects_[i];
    const std::string owner = fmt::format("objects[{}] '{}'", i, object.name);
    if (object.name.empty()) Invalid(fmt::format("objects[{}]: name is empty", i));
    if (!names.insert(object.name).second) Invalid(owner + ": duplicate object name");
    if (object.id == 0) Invalid(owner + ": id must be >= 1 (0 is the background)");
    if (!ids.insert(object.id).second)
      Invalid(fmt::format("{}: duplicate id {}", owner, object.id));
    if (!IsPositiveScale(object.scale)) Invalid(owner + ": scale must be finite and > 0");
    CheckModel(object.model, owner, checked);
    add_model(object.model);
  }
  if (robot_) {
    if (robot_->id == 0) Invalid("robot: id must be >= 1 (0 is the background)");
    if (!ids.insert(robot_->id).second) {
      Invalid(fmt::format("robot: id {} is already an object's", robot_->id));
    }
    // In the head's order (a state by name may come in another), within the limits.
    if (robot_->initial_joints.empty()) robot_->initial_joints = robot_->head.Home();
    robot_->initial_joints = robot_->head.Arrange(robot_->initial_joints);
    robot_->head.CheckLimits(robot_->initial_joints.values());  // names the joint
    for (std::size_t i = 0; i < robot_->parts.size(); ++i) {
      const RobotPart& part = robot_->parts[i];
      const std::string owner = fmt::format("robot.parts[{}]", i);
      if (part.link < 0 || part.link >= robot_->head.tree().num_links()) {
        Invalid(fmt::format("{}: link {} is not a link of the head ({} links)", owner, part.link,
                            robot_->head.tree().num_links()));
      }
      if (!IsRigidPose(part.X_LinkPart)) Invalid(owner + ": X_LinkPart must be a rigid transform");
      if (!IsPositiveScale(part.scale)) Invalid(owner + ": scale must be finite and > 0");
      CheckModel(part.model, owner, checked);
      add_model(part.model);
    }
  }
  std::set<std::string> camera_names;
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    const CameraSpec& camera = cameras_[i];
    const std::string owner = fmt::format("cameras[{}] '{}'", i, camera.name);
    if (camera.name.empty()) Invalid(fmt::format("cameras[{}]: name is empty", i));
    if (!camera_names.insert(camera.name).second) Invalid(owner + ": duplicate camera name");
    if (!(std::isfinite(camera.clip.near) && std::isfinite(camera.clip.far) &&
          camera.clip.near > 0.0 && camera.clip.near < camera.clip.far)) {
      Invalid(fmt::format("{}: clip planes must be 0 < near < far < inf, got near {}, far {}",
                          owner, camera.clip.near, camera.clip.far));
    }
    if (camera.mount == CameraMount::kWorld && !IsRigidPose(camera.X_WC)) {
      Invalid(owner + ": X_WC must be a finite rigid transform");
    }
    if (camera.mount != CameraMount::kWorld && !robot_) {
      Invalid(owner + ": mounted on an eye, but the scene has no robot");
    }
    try {
      camera.sensor.Validate();
    } catch (const InvalidArgument& e) {
      Invalid(owner + ": " + e.what());
    }
  }
}

void SensorSpec::Validate() const {
  const auto check = [](const char* field, double value, double max, const char* what) {
    if (!(std::isfinite(value) && value >= 0.0 && value <= max)) {
      throw InvalidArgument(
          fmt::format("SensorSpec: {} must be {} in [0, {}], got {}", field, what, max, value));
    }
  };
  check("exposure", exposure, 1.0, "seconds");
  check("read_noise_dn", read_noise_dn, 64.0, "a standard deviation in DN");
  check("gain_dn_per_e", gain_dn_per_e, 64.0, "DN per electron");
  if (blur_samples < 1 || blur_samples > 64) {
    throw InvalidArgument(
        fmt::format("SensorSpec: blur_samples must be in [1, 64], got {}", blur_samples));
  }
  if (emva) {
    if (HasNoise()) {
      throw InvalidArgument(
          "SensorSpec: give either the noise figures (read_noise_dn, gain_dn_per_e) or an emva "
          "sensor, not both");
    }
    if (!(exposure > 0.0)) {
      throw InvalidArgument("SensorSpec: an emva sensor needs an exposure > 0 s, got " +
                            fmt::format("{}", exposure));
    }
    emva->Validate();
  }
}

SceneState Scene::InitialState() const {
  SceneState state;
  if (robot_) {
    state.joints = robot_->initial_joints;
    state.joint_velocities = head::JointState(robot_->head.joint_names());  // still
  }
  return state;
}

geometry::Pose Scene::CameraPose(const CameraSpec& camera, const SceneState& state) const {
  if (camera.mount == CameraMount::kWorld || !robot_) return camera.X_WC;
  std::vector<geometry::Pose> X_WL;
  const head::HeadModel& head = robot_->head;
  head.ForwardKinematics(head.Posture(state.joints), &X_WL);
  return head.CameraPose(camera.mount == CameraMount::kLeftEye ? 0 : 1, X_WL);
}

geometry::Pose Scene::ObjectPose(const Object& object, const SceneState& state) const {
  return object.motion.PoseAt(state.time);
}

AppliedControls Scene::ControlsOf(const CameraSpec& camera, const SceneState& state) const {
  const auto found = state.camera_controls.find(camera.name);
  const double file_focus_m = camera.lens.HasDepthOfField() ? camera.lens.focus_distance_m : 0.0;
  return ApplyControls(camera.sensor.exposure, file_focus_m,
                       found == state.camera_controls.end() ? nullptr : &found->second);
}

void Scene::ValidateControls(const SceneState& state, const std::string& what) const {
  for (const auto& [name, controls] : state.camera_controls) {
    if (FindCamera(name) == nullptr) {
      std::string names;
      for (const CameraSpec& camera : cameras_) names += (names.empty() ? "" : ", ") + camera.name;
      throw InvalidArgument(
          fmt::format("{}: camera controls for '{}', a camera the scene does "
                      "not have (it has: {})",
                      what, name, names));
    }
    controls.Validate(fmt::format("{}: camera '{}'", what, name));
  }
}

const CameraSpec* Scene::FindCamera(const std::string& name) const {
  for (const CameraSpec& camera : cameras_) {
    if (camera.name == name) return &camera;
  }
  return nullptr;
}

}  // namespace saccade::scene
