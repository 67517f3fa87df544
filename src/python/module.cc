// The extension module saccade._saccade: one submodule per layer (docs/python.md). The
// package saccade (python/saccade/__init__.py) re-exports them.
#include <pybind11/pybind11.h>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"

using namespace pybind11::literals;

namespace saccade::python {
namespace {

// saccade.Error (a RuntimeError), saccade.InvalidArgument (also a ValueError) and
// saccade.FileError (also an OSError-free Error with file, line and key attributes): the
// C++ exception's message, whole.
// The exception types are never freed: the translator may run until the interpreter ends, and a
// static py::object would be released after it has.
PyObject* g_error = nullptr;
PyObject* g_invalid_argument = nullptr;
PyObject* g_file_error = nullptr;

void BindErrors(py::module_& m) {
  auto& error = *new py::exception<Error>(m, "Error", PyExc_RuntimeError);
  error.doc() = "Base of saccade's exceptions: bad input, with the C++ message (what, where).";
  py::object builtins = py::module_::import("builtins");
  py::object type = builtins.attr("type");
  auto& invalid_argument = *new py::object(
      type("InvalidArgument", py::make_tuple(error, builtins.attr("ValueError")),
           py::dict("__doc__"_a = "A parameter out of its range; the message names it.",
                    "__module__"_a = "saccade")));
  auto& file_error = *new py::object(
      type("FileError", py::make_tuple(error),
           py::dict("__doc__"_a = "A file that cannot be read or parsed: the message starts with "
                                  "file:line: key:, also in the attributes file, line, key.",
                    "__module__"_a = "saccade")));
  m.attr("InvalidArgument") = invalid_argument;
  m.attr("FileError") = file_error;
  g_error = error.ptr();
  g_invalid_argument = invalid_argument.ptr();
  g_file_error = file_error.ptr();
  py::register_exception_translator([](std::exception_ptr pointer) {
    try {
      if (pointer) std::rethrow_exception(pointer);
    } catch (const FileError& e) {
      py::object instance = py::reinterpret_borrow<py::object>(g_file_error)(e.what());
      instance.attr("file") = e.file();
      instance.attr("line") = e.line();
      instance.attr("key") = e.key();
      PyErr_SetObject(g_file_error, instance.ptr());
    } catch (const InvalidArgument& e) {
      PyErr_SetString(g_invalid_argument, e.what());
    } catch (const Error& e) {
      PyErr_SetString(g_error, e.what());
    }
  });
}

}  // namespace
}  // namespace saccade::python

PYBIND11_MODULE(_saccade, m) {
  m.attr("SOURCE_DIR") = SACCADE_SOURCE_DIR;
  using namespace saccade::python;
  m.doc() = "saccade's C++ library: one submodule per layer (docs/python.md)";
  BindErrors(m);
  py::module_ core = m.def_submodule("core", "images and their metadata");
  BindCore(core);
  py::module_ geometry =
      m.def_submodule("geometry", "camera model, calibration files, poses, triangulation");
  BindGeometry(geometry);
  py::module_ head = m.def_submodule("head", "head description, forward and inverse kinematics");
  BindHead(head);
  py::module_ scene = m.def_submodule("scene", "scenes: loading, state");
  BindScene(scene);
  py::module_ render = m.def_submodule("render", "the OpenGL renderer, batch rendering");
  BindRender(render);
  py::module_ runtime =
      m.def_submodule("runtime", "pipelines, signals, methods, Python components");
  BindRuntime(runtime);
  py::module_ hw = m.def_submodule("hw", "the real robot's files: hardware files, servo mappings");
  BindHw(hw);
  py::module_ mcap = m.def_submodule("mcap", "recordings in MCAP: their topics, messages decoded");
  BindRecord(mcap);
}
