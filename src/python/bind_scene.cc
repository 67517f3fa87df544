// saccade.scene: loading a scene file (scenes/portraits.yaml documents the format) and the
// state that changes while the description stays (time, joints, commanded camera controls).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <map>
#include <optional>
#include <string>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace saccade::python {

namespace {

// The state that changes while the description stays, with the camera controls it commands.
void BindSceneState(py::module_& m) {
  using namespace scene;
  py::class_<CameraControls>(m, "CameraControls",
                             "Commanded exposure (s, in (0, 1]), gain (dB, in [0, 48]) and focus "
                             "distance (m, > 0) of one camera; None keeps the file's value.")
      .def(py::init([](std::optional<double> exposure_s, std::optional<double> gain_db,
                       std::optional<double> focus_m) {
             return CameraControls{exposure_s, gain_db, focus_m};
           }),
           "exposure_s"_a = py::none(), "gain_db"_a = py::none(), "focus_m"_a = py::none())
      .def_readwrite("exposure_s", &CameraControls::exposure_s)
      .def_readwrite("gain_db", &CameraControls::gain_db)
      .def_readwrite("focus_m", &CameraControls::focus_m)
      .def("__repr__", [](const CameraControls& c) {
        const auto text = [](const std::optional<double>& v) {
          return v ? std::string(py::str(py::float_(*v))) : std::string("None");
        };
        return "CameraControls(exposure_s=" + text(c.exposure_s) + ", gain_db=" + text(c.gain_db) +
               ", focus_m=" + text(c.focus_m) + ")";
      });

  py::class_<SceneState>(m, "SceneState",
                         "Time (s), joints (rad), joint velocities (rad/s) and commanded camera "
                         "controls by camera name.")
      .def(py::init([](double time, const head::JointState& joints,
                       const head::JointState& velocities,
                       const std::map<std::string, CameraControls>& controls) {
             return SceneState{time, joints, velocities, controls};
           }),
           "time"_a = 0.0, "joints"_a = head::JointState{},
           "joint_velocities"_a = head::JointState{},
           "camera_controls"_a = std::map<std::string, CameraControls>{})
      .def_readwrite("time", &SceneState::time)
      .def_readwrite("joints", &SceneState::joints)
      .def_readwrite("joint_velocities", &SceneState::joint_velocities)
      .def_readwrite("camera_controls", &SceneState::camera_controls,
                     "{camera name: CameraControls}, a copy: assign the whole dict to change it. "
                     "Rendering raises InvalidArgument for an unknown camera or a value out of "
                     "range.");
}

}  // namespace

void BindScene(py::module_& m) {
  using namespace scene;
  BindSceneState(m);

  py::class_<Object>(m, "Object", "Something drawn in the world.")
      .def_readonly("name", &Object::name)
      .def_readonly("id", &Object::id, "Instance id (>= 1) of the id image.")
      .def_property_readonly("source",
                             [](const Object& o) { return o.model ? o.model->source : ""; })
      .def_readonly("scale", &Object::scale);
  py::class_<CameraSpec>(m, "CameraSpec", "A camera of the scene: calibration and mount.")
      .def_readonly("name", &CameraSpec::name)
      .def_readonly("model", &CameraSpec::model)
      .def_property_readonly("mount", [](const CameraSpec& c) {
        switch (c.mount) {
          case CameraMount::kLeftEye:
            return "left_eye";
          case CameraMount::kRightEye:
            return "right_eye";
          default:
            return "world";
        }
      });

  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene", "A loaded, validated world (immutable).")
      .def_static(
          "load",
          [](const std::filesystem::path& path) {
            return std::make_shared<Scene>(Scene::Load(path));
          },
          "path"_a,
          "Loads and validates a scene YAML; raises FileError with file:line: key, also for the "
          "files it refers to.")
      .def_static(
          "from_yaml_string",
          [](const std::string& text, const std::string& source,
             const std::filesystem::path& base_dir) {
            return std::make_shared<Scene>(Scene::FromYamlString(text, source, base_dir));
          },
          "text"_a, "source"_a = "<string>", "base_dir"_a = ".",
          "A scene from YAML text; relative paths resolve against base_dir.")
      .def_property_readonly("objects", &Scene::objects)
      .def_property_readonly("cameras", &Scene::cameras)
      .def_property_readonly("background", &Scene::background)
      .def_property_readonly(
          "head",
          [](const Scene& s) -> py::object {
            return s.robot() ? py::cast(s.robot()->head) : py::none();
          },
          "The robot's HeadDescription, or None when the scene has no robot.")
      .def_property_readonly("robot_id",
                             [](const Scene& s) { return s.robot() ? s.robot()->id : 0u; })
      .def("initial_state", &Scene::InitialState, "The state at time 0 (the robot's joints).")
      .def(
          "camera_pose",
          [](const Scene& s, const std::string& name, const SceneState& state) {
            const CameraSpec* camera = s.FindCamera(name);
            if (camera == nullptr) {
              throw InvalidArgument("Scene.camera_pose: unknown camera '" + name + "'");
            }
            return PoseToMatrix(s.CameraPose(*camera, state));
          },
          "camera"_a, "state"_a, "X_WC of a camera in a state (4x4).")
      .def(
          "object_pose",
          [](const Scene& s, const std::string& name, const SceneState& state) {
            for (const Object& object : s.objects()) {
              if (object.name == name) return PoseToMatrix(s.ObjectPose(object, state));
            }
            throw InvalidArgument("Scene.object_pose: unknown object '" + name + "'");
          },
          "object"_a, "state"_a, "X_WO of an object in a state (4x4).");
}

}  // namespace saccade::python
