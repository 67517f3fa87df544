// saccade.head: the stereo head's description, forward and inverse kinematics (paper
// appendix A). Joint states are PopeyeJoints or any sequence pan, tilt, left, right (rad).
#include <pybind11/eigen.h>
#include <pybind11/operators.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/head/head_description.h"
#include "saccade/head/kinematics.h"

namespace saccade::python {

namespace {

// PopeyeJoints, and the sequences that convert to it.
void BindJointState(py::module_& m) {
  using namespace head;
  py::class_<PopeyeJoints>(m, "JointState", "Joint angles in radians: pan, tilt, left, right.")
      .def(py::init<>())
      .def(py::init([](double pan, double tilt, double left, double right) {
             return PopeyeJoints{pan, tilt, left, right};
           }),
           "pan"_a, "tilt"_a, "left"_a, "right"_a)
      .def(py::init([](const Eigen::Vector4d& v) {
             return PopeyeJoints{v[0], v[1], v[2], v[3]};
           }),
           "values"_a, "From a sequence pan, tilt, left, right.")
      .def_readwrite("pan", &PopeyeJoints::pan)
      .def_readwrite("tilt", &PopeyeJoints::tilt)
      .def_readwrite("left", &PopeyeJoints::left)
      .def_readwrite("right", &PopeyeJoints::right)
      .def(
          "to_array",
          [](const PopeyeJoints& j) { return Eigen::Vector4d(j.pan, j.tilt, j.left, j.right); },
          "numpy array pan, tilt, left, right.")
      .def(
          "__array__",
          [](const PopeyeJoints& j, py::object /*dtype*/) {
            return Eigen::Vector4d(j.pan, j.tilt, j.left, j.right);
          },
          "dtype"_a = py::none())
      .def(py::self == py::self)
      .def("__repr__", [](const PopeyeJoints& j) {
        return "JointState(pan=" + std::to_string(j.pan) + ", tilt=" + std::to_string(j.tilt) +
               ", left=" + std::to_string(j.left) + ", right=" + std::to_string(j.right) + ")";
      });
  py::implicitly_convertible<py::list, PopeyeJoints>();
  py::implicitly_convertible<py::tuple, PopeyeJoints>();
  py::implicitly_convertible<py::array, PopeyeJoints>();
}

// The head description: limits, geometry, the file.
void BindHeadDescription(py::module_& m) {
  using namespace head;
  py::class_<JointLimits>(m, "JointLimits", "Position (rad), velocity (rad/s), acceleration.")
      .def_readonly("min", &JointLimits::min)
      .def_readonly("max", &JointLimits::max)
      .def_readonly("max_velocity", &JointLimits::max_velocity)
      .def_readonly("max_acceleration", &JointLimits::max_acceleration);
  py::class_<HeadGeometry>(m, "HeadGeometry", "Lengths of appendix A, metres.")
      .def_readonly("B", &HeadGeometry::B)
      .def_readonly("D", &HeadGeometry::D)
      .def_readonly("H", &HeadGeometry::H)
      .def_readonly("delta_l", &HeadGeometry::delta_l)
      .def_readonly("delta_r", &HeadGeometry::delta_r);

  py::class_<HeadDescription>(m, "HeadDescription",
                              "A stereo head (robots/popeye.yaml documents the file format).")
      .def_static("from_yaml_file", &HeadDescription::FromYamlFile, "path"_a,
                  "Loads a head description; raises FileError with file:line: key.")
      .def_static("from_yaml_string", &HeadDescription::FromYamlString, "text"_a,
                  "source"_a = "<string>")
      .def_property_readonly("name", &HeadDescription::name)
      .def_property_readonly("geometry", &HeadDescription::geometry)
      .def(
          "limits",
          [](const HeadDescription& h, const std::string& joint) {
            for (Joint j : kAllJoints) {
              if (joint == JointName(j)) return h.limits(j);
            }
            throw InvalidArgument("HeadDescription.limits: unknown joint '" + joint +
                                  "'; expected pan, tilt, left or right");
          },
          "joint"_a, "The limits of 'pan', 'tilt', 'left' or 'right'.")
      .def_property_readonly("X_WB",
                             [](const HeadDescription& h) { return PoseToMatrix(h.X_WB()); })
      .def_property_readonly("left_camera", &HeadDescription::left_camera)
      .def_property_readonly("right_camera", &HeadDescription::right_camera)
      .def("within_limits", &HeadDescription::WithinLimits, "joints"_a)
      .def("check_limits", &HeadDescription::CheckLimits, "joints"_a,
           "Raises InvalidArgument naming the first joint outside its limits.");
}

// Forward kinematics: the frames, and the optical axes' errors.
void BindForwardKinematics(py::module_& m) {
  using namespace head;
  py::class_<HeadFrames>(m, "HeadFrames", "Every frame of the head in the world (4x4 poses).")
      .def_property_readonly("X_WB", [](const HeadFrames& f) { return PoseToMatrix(f.X_WB); })
      .def_property_readonly("X_WN", [](const HeadFrames& f) { return PoseToMatrix(f.X_WN); })
      .def_property_readonly(
          "X_WC", [](const HeadFrames& f) { return PoseToMatrix(f.X_WC); }, "The cyclopean frame.")
      .def_property_readonly("X_WL", [](const HeadFrames& f) { return PoseToMatrix(f.X_WL); })
      .def_property_readonly("X_WR", [](const HeadFrames& f) { return PoseToMatrix(f.X_WR); })
      .def_property_readonly(
          "X_WCamLeft", [](const HeadFrames& f) { return PoseToMatrix(f.X_WCamLeft); },
          "The left camera's optical frame (OpenCV axes).")
      .def_property_readonly("X_WCamRight",
                             [](const HeadFrames& f) { return PoseToMatrix(f.X_WCamRight); })
      .def_readonly("p_WFixation", &HeadFrames::p_WFixation,
                    "Where the optical axes meet, or None.");
  m.def("forward_kinematics", &ForwardKinematics, "head"_a, "joints"_a,
        "The head's frames for a joint state (appendix A); never raises.");
  m.def(
      "axis_errors",
      [](const HeadDescription& head,
         const py::array_t<double, py::array::c_style | py::array::forcecast>& joints,
         const py::array_t<double, py::array::c_style | py::array::forcecast>& p_W) {
        const bool one = joints.ndim() == 1;
        if (!(one ? joints.shape(0) == 4 : joints.ndim() == 2 && joints.shape(1) == 4) ||
            !(p_W.ndim() == joints.ndim() && p_W.shape(p_W.ndim() - 1) == 3 &&
              (one || p_W.shape(0) == joints.shape(0)))) {
          throw InvalidArgument(
              "axis_errors: expected joints (4,) and p_W (3,), or joints (n, 4) and p_W (n, 3)");
        }
        const py::ssize_t n = one ? 1 : joints.shape(0);
        py::array_t<double> out = one ? py::array_t<double>(std::vector<py::ssize_t>{2})
                                      : py::array_t<double>(std::vector<py::ssize_t>{n, 2});
        const double* q = joints.data();
        const double* p = p_W.data();
        double* e = out.mutable_data();
        {
          py::gil_scoped_release release;
          for (py::ssize_t i = 0; i < n; ++i) {
            const Eigen::Vector2d errors =
                AxisErrors(head, PopeyeJoints{q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]},
                           Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
            e[2 * i] = errors[0];
            e[2 * i + 1] = errors[1];
          }
        }
        return out;
      },
      "head"_a, "joints"_a, "p_W"_a,
      "Angle (rad) between each camera's optical axis and the ray to p_W: (left, right); for "
      "joints (n, 4) and points (n, 3), an (n, 2) array, one row a head.");
}

// Inverse kinematics: fixation (appendix A).
void BindInverseKinematics(py::module_& m) {
  using namespace head;
  py::class_<IkResult>(m, "IkResult")
      .def_readonly("joints", &IkResult::joints, "The solution, within the joint limits.")
      .def_property_readonly("reachability",
                             [](const IkResult& r) { return ToString(r.reachability); })
      .def_property_readonly("reachable", &IkResult::reachable)
      .def_readonly("axis_error", &IkResult::axis_error,
                    "Largest angle (rad) between an optical axis and its camera's target ray.")
      .def_readonly("iterations", &IkResult::iterations)
      .def_readonly("message", &IkResult::message);
  m.def(
      "solve_fixation",
      [](const HeadDescription& head, const Eigen::Vector3d& p_W, const std::string& mode,
         const PopeyeJoints& seed) {
        IkOptions options;
        if (mode == "independent") {
          options.mode = VergenceMode::kIndependent;
        } else if (mode != "symmetric") {
          throw InvalidArgument("solve_fixation: mode '" + mode +
                                "'; expected 'symmetric' or 'independent'");
        }
        options.seed = seed;
        return SolveFixation(head, p_W, options);
      },
      "head"_a, "p_W"_a, "mode"_a = "symmetric", "seed"_a = PopeyeJoints{},
      "Inverse kinematics: the joints that bring p_W (world, metres) onto both optical axes.");
  m.def("solve_fixation_closed_form", &SolveFixationClosedForm, "head"_a, "p_W"_a,
        "Closed form of eqs. 10-13 (symmetric vergence, D = H = 0).");
}

}  // namespace

void BindHead(py::module_& m) {
  BindJointState(m);
  BindHeadDescription(m);
  BindForwardKinematics(m);
  BindInverseKinematics(m);
}

}  // namespace saccade::python
