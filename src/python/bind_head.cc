// saccade.head: any stereo head (Head: a head file, with or without a URDF; its forward
// kinematics and fixation) and POPEYE's description with the kinematics of the paper's
// appendix A. POPEYE's joint states are PopeyeJoints or any sequence pan, tilt, left, right
// (rad); any head's are a dict of joint name to value, or a sequence in the head's order.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <pybind11/eigen.h>
#include <pybind11/operators.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/head/fixation.h"
#include "saccade/head/head_description.h"
#include "saccade/head/head_model.h"
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

// A joint state for `head` from Python: a dict by name, a saccade.JointState (POPEYE), or a
// sequence of num_joints values in the head's order.
Eigen::VectorXd PostureOf(const head::HeadModel& head, const py::handle& joints, const char* who) {
  if (joints.is_none()) return head.HomePosture();
  if (py::isinstance<py::dict>(joints) || py::isinstance<head::PopeyeJoints>(joints)) {
    return head.Arrange(joints.cast<head::JointState>()).values();
  }
  const auto q = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(joints);
  if (!q || q.ndim() != 1 || q.shape(0) != head.num_joints()) {
    throw InvalidArgument(std::string(who) + ": expected a dict of joint name to value or " +
                          std::to_string(head.num_joints()) + " values in the order " +
                          fmt::format("{}", fmt::join(*head.joint_names(), ", ")));
  }
  return Eigen::Map<const Eigen::VectorXd>(q.data(), q.shape(0));
}

// One limit of every joint, in the head's order.
Eigen::VectorXd PerJoint(const head::HeadModel& h, double head::JointLimits::*field) {
  Eigen::VectorXd v(h.num_joints());
  for (int j = 0; j < h.num_joints(); ++j) v[j] = h.joint(j).limits.*field;
  return v;
}

py::dict JointInfo(const head::HeadModel& h, int j) {
  const head::JointSettings& s = h.joint(j);
  py::dict info;
  info["name"] = h.joint_name(j);
  info["min"] = s.limits.min;
  info["max"] = s.limits.max;
  info["max_velocity"] = s.limits.max_velocity;
  info["max_acceleration"] = s.limits.max_acceleration;
  info["driven"] = s.driven;
  info["hold"] = s.hold;
  return info;
}

void AddHeadKinematics(py::class_<head::HeadModel>& head_class);

// Any head: the head file (with or without a URDF), its joints, frames and fixation.
void BindHeadModel(py::module_& m) {
  using namespace head;
  py::class_<FixationResult>(m, "FixationResult", "A fixation of any head (Head.fixate).")
      .def_readonly("joints", &FixationResult::joints,
                    "The posture (head order), finite and within the limits.")
      .def_property_readonly("reachability",
                             [](const FixationResult& r) { return ToString(r.reachability); })
      .def_property_readonly("reachable", &FixationResult::reachable)
      .def_readonly("axis_error", &FixationResult::axis_error,
                    "Largest angle (rad) between an optical axis (or the mid-axis) and the "
                    "target.")
      .def_readonly("iterations", &FixationResult::iterations)
      .def_readonly("mid_axis", &FixationResult::mid_axis,
                    "The head cannot verge: the axis midway between its cameras was pointed.")
      .def_readonly("message", &FixationResult::message);

  py::class_<HeadModel> head_class(m, "Head",
                                   "Any stereo head: a head file naming a URDF, or POPEYE's "
                                   "legacy file (docs/formats.md).");
  AddHeadKinematics(head_class);
  head_class
      .def_static("from_file", &HeadModel::FromFile, "path"_a,
                  "Loads a head file (and its URDF); raises FileError naming the file, line "
                  "and element.")
      .def_static(
          "from_yaml_string",
          [](const std::string& text, const std::string& source,
             const std::filesystem::path& folder) {
            return HeadModel::FromYamlString(text, source, folder);
          },
          "text"_a, "source"_a = "<string>", "folder"_a = std::filesystem::path("."))
      .def_property_readonly("name", &HeadModel::name)
      .def_property_readonly(
          "joint_names", [](const HeadModel& h) { return *h.joint_names(); },
          "The actuated joints, in the head's order (the URDF's).")
      .def_property_readonly("num_joints", &HeadModel::num_joints)
      .def_property_readonly(
          "driven_joints",
          [](const HeadModel& h) {
            std::vector<std::string> names;
            for (int j = 0; j < h.num_joints(); ++j) {
              if (h.joint(j).driven) names.push_back(h.joint_name(j));
            }
            return names;
          },
          "The joints saccade commands; the others are held.")
      .def(
          "joint",
          [](const HeadModel& h, const std::string& name) {
            const int j = h.FindJoint(name);
            if (j < 0) {
              throw InvalidArgument(fmt::format("Head.joint: no joint '{}'; the joints are: {}",
                                                name, fmt::join(*h.joint_names(), ", ")));
            }
            return JointInfo(h, j);
          },
          "name"_a, "min, max (rad or m), max_velocity, max_acceleration, driven, hold.")
      .def_property_readonly("limits_min",
                             [](const HeadModel& h) { return PerJoint(h, &JointLimits::min); })
      .def_property_readonly("limits_max",
                             [](const HeadModel& h) { return PerJoint(h, &JointLimits::max); })
      .def_property_readonly(
          "max_velocity",
          [](const HeadModel& h) { return PerJoint(h, &JointLimits::max_velocity); })
      .def("home", &HeadModel::HomePosture, "The home posture (head order).")
      .def_property_readonly("X_WB", [](const HeadModel& h) { return PoseToMatrix(h.X_WB()); })
      .def_property_readonly("left_camera", [](const HeadModel& h) { return h.camera(0).model; })
      .def_property_readonly("right_camera", [](const HeadModel& h) { return h.camera(1).model; })
      .def_property_readonly("urdf", &HeadModel::urdf_xml,
                             "The URDF's text ('' for a head file without one).")
      .def_property_readonly(
          "can_verge", [](const HeadModel& h) { return FixationSolver(h).can_verge(); },
          "Whether some joint turns one camera without the other.");
}

// Head: its limits, poses and fixation.
void AddHeadKinematics(py::class_<head::HeadModel>& head_class) {
  using namespace head;
  head_class
      .def(
          "within_limits",
          [](const HeadModel& h, const py::object& joints) {
            return h.WithinLimits(PostureOf(h, joints, "Head.within_limits"));
          },
          "joints"_a)
      .def(
          "check_limits",
          [](const HeadModel& h, const py::object& joints) {
            h.CheckLimits(PostureOf(h, joints, "Head.check_limits"));
          },
          "joints"_a, "Raises InvalidArgument naming the first joint outside its limits.")
      .def(
          "link_poses",
          [](const HeadModel& h, const py::object& joints) {
            std::vector<geometry::Pose> X_WL;
            h.ForwardKinematics(PostureOf(h, joints, "Head.link_poses"), &X_WL);
            py::dict out;
            for (size_t l = 0; l < X_WL.size(); ++l) {
              out[py::str(h.tree().link_name(static_cast<int>(l)))] = PoseToMatrix(X_WL[l]);
            }
            return out;
          },
          "joints"_a = py::none(), "Every link's pose in the world (4x4), by link name.")
      .def(
          "camera_poses",
          [](const HeadModel& h, const py::object& joints) {
            const Eigen::VectorXd q = PostureOf(h, joints, "Head.camera_poses");
            const auto X = h.CameraPoses(h.State(q));
            return py::make_tuple(PoseToMatrix(X[0]), PoseToMatrix(X[1]));
          },
          "joints"_a = py::none(),
          "The left and right cameras' optical frames (OpenCV axes) in the world, 4x4.")
      .def(
          "fixate",
          [](const HeadModel& h, const Eigen::Vector3d& p_W, const py::object& seed) {
            FixationOptions options;
            if (!seed.is_none()) options.seed = PostureOf(h, seed, "Head.fixate");
            py::gil_scoped_release release;
            return SolveFixation(h, p_W, options);
          },
          "p_W"_a, "seed"_a = py::none(),
          "The posture that puts both optical axes through p_W (world, m), by the head "
          "file's fixation rule; an unreachable target is a result with the reason.")
      .def(
          "axis_errors",
          [](const HeadModel& h,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& joints,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& p_W) {
            const py::ssize_t n_joints = h.num_joints();
            const bool one = joints.ndim() == 1;
            if (!(one ? joints.shape(0) == n_joints
                      : joints.ndim() == 2 && joints.shape(1) == n_joints) ||
                !(p_W.ndim() == joints.ndim() && p_W.shape(p_W.ndim() - 1) == 3 &&
                  (one || p_W.shape(0) == joints.shape(0)))) {
              throw InvalidArgument(fmt::format(
                  "Head.axis_errors: expected joints ({0},) and p_W (3,), or joints (n, {0}) "
                  "and p_W (n, 3)",
                  n_joints));
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
                    AxisErrors(h, Eigen::Map<const Eigen::VectorXd>(q + n_joints * i, n_joints),
                               Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
                e[2 * i] = errors[0];
                e[2 * i + 1] = errors[1];
              }
            }
            return out;
          },
          "joints"_a, "p_W"_a,
          "Angle (rad) between each camera's optical axis and the ray to p_W: (left, right); "
          "for joints (n, num_joints) and points (n, 3), an (n, 2) array.")
      .def("__repr__", [](const HeadModel& h) {
        return fmt::format("<Head '{}': {}>", h.name(), fmt::join(*h.joint_names(), ", "));
      });
}

}  // namespace

void BindHead(py::module_& m) {
  BindJointState(m);
  BindHeadDescription(m);
  BindForwardKinematics(m);
  BindInverseKinematics(m);
  BindHeadModel(m);
}

}  // namespace saccade::python
