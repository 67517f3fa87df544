#pragma once
// The world: lights, ground, objects (3D models, pictures, primitives) with scripted motion,
// cameras, and the robot head. A Scene is an immutable description; what changes with time
// (simulation time, joint angles) lives in SceneState, and every pose is a pure function of
// the two (DESIGN.md: descriptions apart from state).
//
// Frames: world W right-handed, z up; an object's frame O is placed by X_WO(t). Models are
// in metres in their own frame, after the file's unit scale. Texture coordinates follow
// OpenGL and Assimp: uv (0, 0) is the bottom-left corner of the texture image.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/gl_projection.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/head_model.h"
#include "saccade/head/joint_state.h"
#include "saccade/scene/camera_controls.h"
#include "saccade/scene/camera_optics.h"
#include "saccade/scene/emva_sensor.h"

namespace saccade::scene {

/// A decoded texture image (kRgb8 or kRgba8, row 0 at the top) and where it came from.
struct Texture {
  std::string source;
  Image image;
};

/// Surface appearance: a colour (linear RGBA in [0, 1]) times an optional texture, lit by
/// Lambert diffuse plus Blinn-Phong specular.
struct Material {
  Eigen::Vector4f base_color{1.0f, 1.0f, 1.0f, 1.0f};
  std::shared_ptr<const Texture> texture;  ///< may be null
  float specular = 0.0f;                   ///< specular strength in [0, 1]
  float shininess = 32.0f;                 ///< Blinn-Phong exponent
};

/// One triangle mesh with a single material. Normals are unit, one per position; uvs are
/// either empty or one per position.
struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<uint32_t> indices;  ///< three per triangle, each < positions.size()
  int material = 0;               ///< index into Model::materials
};

/// Geometry loaded once and shared by every object that shows it (seed section 5.2).
struct Model {
  std::string source;  ///< the file path, or "box", "sphere", "plane", "picture:<image>"
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  Eigen::AlignedBox3f bounds;  ///< in the model frame
};

/// A pose as a pure function of time: static, through timed waypoints (position linear,
/// orientation slerp; optionally looping), or at constant linear and angular velocity.
class Motion {
 public:
  struct Waypoint {
    double time = 0.0;  ///< seconds, strictly increasing
    geometry::Pose pose = geometry::Pose::Identity();
  };

  /// Always at X_WO.
  static Motion Static(const geometry::Pose& X_WO);
  /// Through the waypoints (at least one, times strictly increasing): held before the first
  /// and after the last unless `loop`, in which case time wraps around the last waypoint's
  /// time, going back to the first pose. Throws InvalidArgument on bad times.
  static Motion Waypoints(std::vector<Waypoint> waypoints, bool loop);
  /// X_WO(t) = translate(v t) * X_WO(0) rotated by angle |w| t about w (world axes, through
  /// the object's origin). v in m/s, w in rad/s.
  static Motion ConstantVelocity(const geometry::Pose& X_WO_at_0, const Eigen::Vector3d& v_W,
                                 const Eigen::Vector3d& w_W);

  /// X_WO at time t (seconds). Never throws; a pure function of t.
  geometry::Pose PoseAt(double t) const;
  bool IsStatic() const { return kind_ == Kind::kStatic; }

 private:
  enum class Kind { kStatic, kWaypoints, kConstantVelocity };
  Kind kind_ = Kind::kStatic;
  std::vector<Waypoint> waypoints_{Waypoint{}};
  bool loop_ = false;
  Eigen::Vector3d v_W_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_W_ = Eigen::Vector3d::Zero();
};

/// Something drawn in the world.
struct Object {
  std::string name;
  uint32_t id = 0;  ///< instance id, >= 1 and unique in the scene (0 is the background)
  std::shared_ptr<const Model> model;
  Eigen::Vector3d scale{1.0, 1.0, 1.0};  ///< per axis of the object frame, > 0
  Motion motion;                         ///< X_WO(t)
};

struct Light {
  enum class Type { kAmbient, kDirectional, kPoint };
  Type type = Type::kDirectional;
  Eigen::Vector3f color{1.0f, 1.0f, 1.0f};  ///< linear RGB, times intensity
  float intensity = 1.0f;
  Eigen::Vector3d direction_W{0.0, 0.0, -1.0};  ///< kDirectional: the way the light travels
  Eigen::Vector3d position_W{0.0, 0.0, 3.0};    ///< kPoint
  /// kPoint: intensity / (1 + attenuation * d^2).
  double attenuation = 0.0;
};

/// The ground: a finite plane z = 0 in the world, centred on the origin.
struct Ground {
  enum class Pattern { kPlain, kGrid, kChecker };
  bool enabled = true;
  double size = 10.0;  ///< side length, metres
  Pattern pattern = Pattern::kGrid;
  double cell = 0.5;         ///< grid spacing or checker square, metres
  double line_width = 0.01;  ///< grid lines, metres
  Eigen::Vector3f color{0.55f, 0.55f, 0.55f};
  Eigen::Vector3f color2{0.25f, 0.25f, 0.25f};  ///< grid lines / the other checker squares
};

/// What the sensor does after the lens: exposure (motion blur) and noise, in digital numbers
/// (DN: the 0..255 scale of the 8-bit image), or an EMVA 1288 sensor. All off by default.
struct SensorSpec {
  /// Exposure time, seconds, >= 0 (at most 1). The frame of time t integrates the scene over
  /// [t - exposure / 2, t + exposure / 2]: moving objects and a moving head blur; a still
  /// scene renders exactly as with no exposure. 0: an instant.
  double exposure = 0.0;
  /// Sub-frames rendered over the exposure when something moves during it, 1 .. 64 (1: no
  /// blur whatever the exposure).
  int blur_samples = 8;
  /// Read noise: Gaussian, standard deviation in DN, >= 0 (at most 64).
  double read_noise_dn = 0.0;
  /// Shot noise as EMVA 1288's overall system gain K, DN per electron, >= 0 (at most 64): a
  /// signal of S DN has shot-noise variance K * S DN^2 (Gaussian approximation of Poisson).
  /// 0: no shot noise.
  double gain_dn_per_e = 0.0;
  /// Seed of the noise. Each camera and frame draws its own stream from the seed, the
  /// camera's name and the frame index: the same seed gives the same frames.
  uint64_t seed = 0;
  /// An EMVA 1288 sensor (emva_sensor.h, docs/sensor.md) instead of the two noise figures
  /// above (which must then be 0): photons from the rendered value and `exposure` (> 0),
  /// shot and dark noise, DSNU/PRNU fixed per camera from `seed`, full well, gain, bit depth.
  std::optional<EmvaSensor> emva;
  /// The sensor's colour: filter array, demosaicing, white balance, tone curve (camera_optics.h,
  /// docs/camera-pixels.md); applied after the noise. Default: none.
  ColorSpec color{};

  /// The legacy noise (read_noise_dn, gain_dn_per_e), not the EMVA sensor.
  bool HasNoise() const { return read_noise_dn > 0.0 || gain_dn_per_e > 0.0; }
  bool HasEmva() const { return emva.has_value(); }
  bool HasBlur() const { return exposure > 0.0 && blur_samples > 1; }
  /// Throws InvalidArgument naming the field and the value when one is out of range.
  void Validate() const;
};

/// Where a camera is mounted.
enum class CameraMount { kWorld, kLeftEye, kRightEye };

/// A camera of the scene: its calibration and its mount.
struct CameraSpec {
  std::string name;  ///< unique; used for output folders ("left", "right", "rig")
  geometry::CameraModel model;
  CameraMount mount = CameraMount::kWorld;
  /// kWorld: the optical frame in the world. Eye mounts take their pose from the head.
  geometry::Pose X_WC = geometry::Pose::Identity();
  geometry::ClipPlanes clip{0.05, 50.0};
  SensorSpec sensor;
  /// The lens's photometric side: vignetting and depth of field (camera_optics.h), applied
  /// before the sensor. Default: none.
  LensSpec lens{};
};

/// A piece of the robot's drawn body, rigidly attached to one link of the head's tree.
struct RobotPart {
  int link = 0;  ///< the link's index in the head's KinematicTree
  geometry::Pose X_LinkPart = geometry::Pose::Identity();
  std::shared_ptr<const Model> model;
  Eigen::Vector3d scale{1.0, 1.0, 1.0};
};

/// The head placed in the world (its description's pose), its initial joints and its body.
struct Robot {
  head::HeadModel head;
  head::JointState initial_joints;  ///< the head's joints, in its order
  bool visible = true;
  /// Built by the loader: a URDF's visuals, or POPEYE's body from primitives.
  std::vector<RobotPart> parts;
  /// Instance id of every robot part (one id for the whole robot), >= 1.
  uint32_t id = 0;
};

/// What changes while the description stays: time and joint angles.
struct SceneState {
  double time = 0.0;        ///< seconds
  head::JointState joints;  ///< the robot's joints (empty without a robot)
  /// Joint velocities (rad/s) at `time`: during a camera's exposure the joints move at this
  /// constant rate, which blurs the eye cameras' images (SensorSpec::exposure). Empty or
  /// zero: still.
  head::JointState joint_velocities;
  /// Commanded exposure, gain and focus by camera name (camera_controls.h); a camera absent
  /// here, or a control absent from its entry, keeps the file's value. Every name must be a
  /// camera of the scene and every value in range (Renderer::Submit throws InvalidArgument).
  std::map<std::string, CameraControls> camera_controls;
};

/// How Scene::Load reads a file, beyond what the file says.
struct LoadOptions {
  /// A head file (robots/*.yaml) that replaces the scene's robot head (`saccade demo --head`):
  /// the robot stands where that file's `pose` puts it, at its home joints; the scene's
  /// robot `head`, `pose`, `joints` / `joints_deg` and eye `calibration` (written for its own
  /// head) are not used; `visible`, `id` and each eye's `clip` and `sensor` apply. Empty: the
  /// scene's own head. With a head, a scene without a robot is an error.
  std::filesystem::path head;
};

/// A loaded, validated world. Immutable; cheap to share by reference.
class Scene {
 public:
  /// Loads and fully validates a scene YAML (scenes/portraits.yaml documents the format).
  /// Relative paths inside resolve against the scene file's folder. Every error throws
  /// saccade::FileError "file:line: key: what was expected, what was got", including those of
  /// the files it refers to (models, images, head descriptions, calibrations). A model file is
  /// loaded once however many objects show it.
  static Scene Load(const std::filesystem::path& path, const LoadOptions& options = {});
  /// Same from text; `source` names it in errors, `base_dir` resolves relative paths.
  static Scene FromYamlString(const std::string& text, const std::string& source,
                              const std::filesystem::path& base_dir,
                              const LoadOptions& options = {});

  Eigen::Vector3f background() const { return background_; }  ///< sky colour, linear RGB
  const std::vector<Light>& lights() const { return lights_; }
  const Ground& ground() const { return ground_; }
  const std::vector<Object>& objects() const { return objects_; }
  const std::vector<CameraSpec>& cameras() const { return cameras_; }
  const std::optional<Robot>& robot() const { return robot_; }
  /// Every distinct model, once each (what a renderer uploads).
  const std::vector<std::shared_ptr<const Model>>& models() const { return models_; }

  /// The state at time 0: the robot's initial joints.
  SceneState InitialState() const;
  /// X_WC of a camera in a state (FK for eye-mounted cameras).
  geometry::Pose CameraPose(const CameraSpec& camera, const SceneState& state) const;
  /// The exposure, gain and focus a camera takes its frame of `state` with: the state's
  /// commands over the file's values (camera_controls.h). Never throws.
  AppliedControls ControlsOf(const CameraSpec& camera, const SceneState& state) const;
  /// Throws InvalidArgument, starting with `what`, when state.camera_controls names a camera
  /// the scene does not have or holds a value out of range.
  void ValidateControls(const SceneState& state, const std::string& what) const;
  /// X_WO of an object in a state.
  geometry::Pose ObjectPose(const Object& object, const SceneState& state) const;
  /// The camera named `name`, or nullptr.
  const CameraSpec* FindCamera(const std::string& name) const;

  /// Builds a scene in code (tests, tools). Validates like Load: throws InvalidArgument.
  Scene(Eigen::Vector3f background, std::vector<Light> lights, Ground ground,
        std::vector<Object> objects, std::vector<CameraSpec> cameras, std::optional<Robot> robot);

 private:
  Eigen::Vector3f background_;
  std::vector<Light> lights_;
  Ground ground_;
  std::vector<Object> objects_;
  std::vector<CameraSpec> cameras_;
  std::optional<Robot> robot_;
  std::vector<std::shared_ptr<const Model>> models_;
};

/// Primitive models, in metres: a unit cube centred on the origin, a sphere of radius 0.5, a
/// 1 x 1 plane z = 0 facing +z. `color` is the material's base colour.
std::shared_ptr<const Model> MakeBox(const Eigen::Vector4f& color);
std::shared_ptr<const Model> MakeSphere(const Eigen::Vector4f& color, int segments = 32);
/// A cylinder of radius 0.5 and length 1 along z, centred on the origin (URDF's <cylinder>).
std::shared_ptr<const Model> MakeCylinder(const Eigen::Vector4f& color, int segments = 32);
std::shared_ptr<const Model> MakePlane(const Eigen::Vector4f& color);
/// A picture: the image on a plane `height` metres high, width from the image's aspect,
/// standing upright in its frame: it lies in the plane x = 0, faces +x, its top edge towards
/// +z and its right edge (seen from +x) towards +y; centred on the origin.
std::shared_ptr<const Model> MakePicture(std::shared_ptr<const Texture> texture, double height);

}  // namespace saccade::scene
