// saccade.hw: the real robot's files. A hardware file (pipelines/hardware/*.yaml) names the
// components that stand for the robot; read_pipeline_spec shows what a pipeline becomes with
// one (the one line that swaps the simulator for the robot), and servo_mapping what a head
// description says about the servos that drive its joints.
#include <pybind11/stl.h>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/head/head_description.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::python {

void BindHw(py::module_& m) {
  py::class_<head::ServoMapping>(m, "ServoMapping",
                                 "servo_angle = zero_offset + direction * gear_ratio * joint_angle")
      .def_readonly("id", &head::ServoMapping::id)
      .def_readonly("zero_offset", &head::ServoMapping::zero_offset)
      .def_readonly("direction", &head::ServoMapping::direction)
      .def_readonly("gear_ratio", &head::ServoMapping::gear_ratio)
      .def("servo_angle", &head::ServoMapping::ServoAngle, "joint_angle"_a)
      .def("joint_angle", &head::ServoMapping::JointAngle, "servo_angle"_a);
  m.def(
      "servo_mapping",
      [](const head::HeadDescription& head, const std::string& joint) -> py::object {
        for (head::Joint j : head::kAllJoints) {
          if (joint == head::JointName(j)) {
            return head.servo(j) ? py::cast(*head.servo(j)) : py::none();
          }
        }
        throw InvalidArgument("servo_mapping: unknown joint '" + joint +
                              "'; expected pan, tilt, left or right");
      },
      "head"_a, "joint"_a, "The servo that drives a joint (the description's `servo:`), or None.");
  m.def(
      "read_pipeline_spec",
      [](const std::string& path, const std::string& hardware) {
        const runtime::PipelineSpec spec = runtime::LoadPipelineFile(path, hardware);
        py::list components;
        for (const runtime::ComponentSpec& c : spec.components) {
          components.append(py::dict("name"_a = c.name, "type"_a = c.type,
                                     "params"_a = JsonToPython(c.params),
                                     "params_file"_a = c.params_file, "line"_a = c.line));
        }
        py::dict resources;
        for (const auto& [kind, resource] : spec.resources)
          resources[py::str(kind)] = resource.path;
        return py::dict("file"_a = spec.file, "hardware_file"_a = spec.hardware_file,
                        "components"_a = components, "resources"_a = resources,
                        "seed"_a = spec.seed, "step"_a = spec.clock.step,
                        "steps"_a = spec.clock.steps);
      },
      "path"_a, "hardware"_a = "",
      "Parses a pipeline file and its hardware file (`hardware` replaces the file's own line) "
      "without building it: {'file', 'hardware_file', 'components': [{'name', 'type', "
      "'params', 'params_file', 'line'}], 'resources', 'seed', 'step', 'steps'}. Raises "
      "FileError with file:line: key.");
}

}  // namespace saccade::python
