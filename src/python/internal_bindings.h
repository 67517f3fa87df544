#pragma once
// The pieces of the extension module saccade._saccade (module.cc), one binding function per
// layer, and the conversions they share. Private to src/python.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <nlohmann/json.hpp>

#include "saccade/core/image.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/head_description.h"
#include "saccade/head/joint_state.h"

namespace saccade::python {

namespace py = pybind11;
using namespace pybind11::literals;  // NOLINT: "name"_a keyword arguments

void BindCore(py::module_& m);
void BindGeometry(py::module_& m);
void BindHead(py::module_& m);
void BindScene(py::module_& m);
void BindRender(py::module_& m);
void BindRuntime(py::module_& m);
void BindHw(py::module_& m);
void BindRecord(py::module_& m);

/// The C++ owner of an image's pixels, as Python sees it (saccade.Image): numpy arrays made
/// from it borrow its memory and keep it alive through their `base`.
struct ImageRef {
  std::shared_ptr<const Image> image;
};

/// A read-only numpy array over the image's pixels (height x width [x channels]), no copy;
/// its base is a saccade.Image holding `image`. None for a null image.
py::object ImageArray(std::shared_ptr<const Image> image);

/// A 4x4 homogeneous matrix of a pose, and back (checks that it is a rigid transform).
Eigen::Matrix4d PoseToMatrix(const geometry::Pose& pose);
geometry::Pose PoseFromMatrix(const Eigen::Matrix4d& matrix, const char* what);

/// JSON to Python (dict, list, str, int, float, bool, None) and back. FromPython throws
/// InvalidArgument naming `what` for a value JSON cannot hold.
py::object JsonToPython(const nlohmann::json& json);
nlohmann::json JsonFromPython(const py::handle& value, const std::string& what);

}  // namespace saccade::python

// A head's joints (head::JointState, any head) in Python: POPEYE's four joints are the
// saccade.JointState class (pan, tilt, left, right) as always; any other head's are a dict of
// joint name to value in the head's order. Back: a saccade.JointState, a dict of name to value
// (arranged by name where the head takes it), a sequence of 4 numbers (POPEYE's order), or
// None (no joints).
namespace pybind11::detail {
template <>
struct type_caster<saccade::head::JointState> {
 public:
  PYBIND11_TYPE_CASTER(saccade::head::JointState, const_name("JointState | dict[str, float]"));

  bool load(handle source, bool) {
    namespace head = saccade::head;
    if (source.is_none()) {
      value = head::JointState();
      return true;
    }
    if (isinstance<dict>(source)) {
      auto names = std::make_shared<head::JointNames>();
      std::vector<double> values;
      for (auto item : reinterpret_borrow<dict>(source)) {
        names->push_back(item.first.cast<std::string>());
        values.push_back(item.second.cast<double>());
      }
      value = head::JointState(std::move(names),
                               Eigen::Map<Eigen::VectorXd>(values.data(), values.size()));
      return true;
    }
    try {
      const auto q = source.cast<head::PopeyeJoints>();  // implicit from sequences of 4
      value = head::JointState::Popeye(q.pan, q.tilt, q.left, q.right);
      return true;
    } catch (const cast_error&) {
      return false;
    }
  }

  static handle cast(const saccade::head::JointState& joints, return_value_policy, handle) {
    namespace head = saccade::head;
    if (joints.names() == *head::JointState::PopeyeNames()) {
      return pybind11::cast(head::PopeyeJoints{joints[0], joints[1], joints[2], joints[3]})
          .release();
    }
    dict out;
    for (int i = 0; i < joints.size(); ++i) out[pybind11::str(joints.name(i))] = joints[i];
    return out.release();
  }
};
}  // namespace pybind11::detail
