#pragma once
// The pieces of the extension module saccade._saccade (module.cc), one binding function per
// layer, and the conversions they share. Private to src/python.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <nlohmann/json.hpp>

#include "saccade/core/image.h"
#include "saccade/geometry/pose.h"

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
