// saccade.scene: loading a scene file (scenes/portraits.yaml documents the format) and the
// state that changes while the description stays (time, joints).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace saccade::python {

void BindScene(py::module_& m) {
  using namespace scene;
  py::class_<SceneState>(m, "SceneState", "Time (s), joints (rad) and joint velocities (rad/s).")
      .def(py::init(
               [](double time, const head::JointState& joints, const head::JointState& velocities) {
                 return SceneState{time, joints, velocities, {}};
               }),
           "time"_a = 0.0, "joints"_a = head::JointState{},
           "joint_velocities"_a = head::JointState{})
      .def_readwrite("time", &SceneState::time)
      .def_readwrite("joints", &SceneState::joints)
      .def_readwrite("joint_velocities", &SceneState::joint_velocities);

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
