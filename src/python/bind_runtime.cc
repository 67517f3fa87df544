// saccade.runtime: pipelines from YAML (hardware files included), stepped from Python; any
// output read as it is emitted (images as numpy arrays without a copy, other messages as
// dicts in their JSON form); any method called; components written in Python registered as
// types that pipeline files name.
//
// Stepping: Pipeline.step runs runtime::Stepper's step (scheduler.h), the one runtime::RunPipeline
// loops over: delayed messages delivered, the components level by level (a level's at the same
// time on the pipeline's threads), their inputs marked seen; simulated time step * dt (or
// clock.source's stamps) whatever the file's clock. A failing component raises saccade.Error
// "component 'name' failed at step k: ..." after the step (which on_error: stop ends at the
// failure). The GIL is released while C++ components step; a Python component (thread-affine:
// on the calling thread) takes it back for its own step.
#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <map>
#include <optional>

#include "python/internal_bindings.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/dds/transport.h"
#include "saccade/runtime/component_registry.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"

namespace saccade::python {
namespace {

using runtime::Component;
using runtime::ImageMessage;
using runtime::InputBase;
using runtime::OutputBase;

// The Python error being handled, as one line "Type: message" (call with the GIL held, inside
// the catch of error_already_set).
std::string PythonErrorText(const py::error_already_set& error) {
  return std::string(error.what());
}

// A numpy array (height x width [x channels]) as a new Image; a saccade.Image as itself.
std::shared_ptr<const Image> ImageFromPython(const py::handle& value, const std::string& what) {
  if (py::isinstance<ImageRef>(value)) return value.cast<const ImageRef&>().image;
  py::array array = py::array::ensure(value);
  if (!array) throw InvalidArgument(what + ": expected a numpy image array or a saccade.Image");
  PixelFormat format;
  const int channels = array.ndim() == 3 ? static_cast<int>(array.shape(2)) : 1;
  if (array.dtype().is(py::dtype::of<uint8_t>()) && channels == 3 && array.ndim() == 3) {
    format = PixelFormat::kRgb8;
  } else if (array.dtype().is(py::dtype::of<uint8_t>()) && channels == 4 && array.ndim() == 3) {
    format = PixelFormat::kRgba8;
  } else if (array.dtype().is(py::dtype::of<uint8_t>()) && array.ndim() == 2) {
    format = PixelFormat::kGray8;
  } else if (array.dtype().is(py::dtype::of<float>()) && array.ndim() == 2) {
    format = PixelFormat::kFloat32;
  } else if (array.dtype().is(py::dtype::of<uint32_t>()) && array.ndim() == 2) {
    format = PixelFormat::kUint32;
  } else {
    throw InvalidArgument(what +
                          ": an image array must be uint8 HxWx3, HxWx4 or HxW, float32 "
                          "HxW or uint32 HxW; got " +
                          std::string(py::str(array.dtype())) + " with " +
                          std::to_string(array.ndim()) + " dimensions");
  }
  py::array contiguous = py::array::ensure(array, py::array::c_style);
  auto image = std::make_shared<Image>(static_cast<int>(array.shape(1)),
                                       static_cast<int>(array.shape(0)), format);
  std::memcpy(image->data(), contiguous.data(), image->size_bytes());
  return image;
}

// What the bindings do with a message type: declare ports, read an input, emit from Python.
struct PortOps {
  std::function<InputBase&(Component&, const std::string&, bool)> add_input;
  std::function<OutputBase&(Component&, const std::string&)> add_output;
  std::function<py::object(const InputBase&)> read;
  std::function<void(const OutputBase&, const py::handle&)> emit;
};

class PyComponent;

template <runtime::Message T>
PortOps MakePortOps();

std::map<std::string, PortOps>& PortTable();

// A component whose behaviour is a Python object (see python/saccade/components.py):
//   inputs / outputs: {port: message type} (an input's value may be (type, required));
//   configure(params), start(), step(context, inputs) -> {output: message} or None, stop().
class PyComponent final : public Component {
 public:
  explicit PyComponent(py::object impl) : impl_(std::move(impl)) {
    const auto declare = [&](const char* attr, bool input) {
      if (!py::hasattr(impl_, attr)) return;
      py::dict ports = impl_.attr(attr).cast<py::dict>();
      for (const auto& [key, value] : ports) {
        const std::string name = py::str(key);
        std::string type;
        bool required = false;
        if (py::isinstance<py::tuple>(value)) {
          auto tuple = value.cast<py::tuple>();
          type = tuple[0].cast<std::string>();
          required = tuple.size() > 1 && tuple[1].cast<bool>();
        } else {
          type = value.cast<std::string>();
        }
        const auto found = PortTable().find(type);
        if (found == PortTable().end()) {
          std::string known;
          for (const auto& [t, ops] : PortTable()) known += (known.empty() ? "" : ", ") + t;
          throw InvalidArgument(
              fmt::format("Python component: {} '{}': unknown message type "
                          "'{}'; expected one of {}",
                          input ? "input" : "output", name, type, known));
        }
        if (input) {
          inputs_by_name_.emplace(
              name,
              std::make_pair(&found->second.add_input(*this, name, required), &found->second));
        } else {
          outputs_by_name_.emplace(
              name, std::make_pair(&found->second.add_output(*this, name), &found->second));
        }
      }
    };
    declare("inputs", true);
    declare("outputs", false);
  }

  ~PyComponent() override {
    py::gil_scoped_acquire gil;
    impl_ = py::object();
  }

  template <runtime::Message T>
  runtime::Input<T>& NewInput(const std::string& name, bool required) {
    return AddInput<T>(name, required);
  }
  template <runtime::Message T>
  runtime::Output<T>& NewOutput(const std::string& name) {
    return AddOutput<T>(name);
  }

  void Configure(const nlohmann::json& params) override {
    py::gil_scoped_acquire gil;
    if (py::hasattr(impl_, "configure")) {
      Call("configure", [&] { impl_.attr("configure")(JsonToPython(params)); });
    } else if (!params.is_null() && !params.empty()) {
      throw InvalidArgument("this Python component takes no params (it has no configure)");
    }
  }
  void Start() override {
    py::gil_scoped_acquire gil;
    if (py::hasattr(impl_, "start")) Call("start", [&] { impl_.attr("start")(); });
  }
  void Stop() override {
    py::gil_scoped_acquire gil;
    if (py::hasattr(impl_, "stop")) Call("stop", [&] { impl_.attr("stop")(); });
  }
  // Python objects are not for the scheduler's other threads.
  bool thread_affine() const override { return true; }

  void Step(const runtime::StepContext& context) override {
    py::gil_scoped_acquire gil;
    Call("step", [&] {
      py::dict inputs;
      for (const auto& [name, port] : inputs_by_name_) {
        inputs[py::str(name)] =
            port.first->has_value() ? port.second->read(*port.first) : py::none();
      }
      py::dict ctx("step"_a = context.step, "time"_a = context.time, "dt"_a = context.dt,
                   "seed"_a = context.seed);
      py::object result = impl_.attr("step")(ctx, inputs);
      if (result.is_none()) return;
      for (const auto& [key, value] : result.cast<py::dict>()) {
        const std::string name = py::str(key);
        const auto found = outputs_by_name_.find(name);
        if (found == outputs_by_name_.end()) {
          throw InvalidArgument("step returned output '" + name + "', which it did not declare");
        }
        if (!value.is_none()) found->second.second->emit(*found->second.first, value);
      }
    });
  }

  py::object impl() const { return impl_; }

 private:
  // Calls into Python; a Python exception becomes saccade::Error with its text (so that the
  // pipeline names the component and step), raised after the Python error state is cleared.
  template <class F>
  void Call(const char* what, F&& f) {
    std::string message;
    try {
      f();
      return;
    } catch (py::error_already_set& error) {
      message = PythonErrorText(error);
    } catch (py::cast_error& error) {
      message = std::string("a value of the wrong type: ") + error.what();
    }
    throw Error(std::string(what) + ": " + message);
  }

  py::object impl_;
  std::map<std::string, std::pair<InputBase*, const PortOps*>> inputs_by_name_;
  std::map<std::string, std::pair<OutputBase*, const PortOps*>> outputs_by_name_;
};

template <runtime::Message T>
PortOps MakePortOps() {
  PortOps ops;
  ops.add_input = [](Component& c, const std::string& name, bool required) -> InputBase& {
    return static_cast<PyComponent&>(c).NewInput<T>(name, required);
  };
  ops.add_output = [](Component& c, const std::string& name) -> OutputBase& {
    return static_cast<PyComponent&>(c).NewOutput<T>(name);
  };
  if constexpr (std::is_same_v<T, ImageMessage>) {
    ops.read = [](const InputBase& input) -> py::object {
      const auto& image = static_cast<const runtime::Input<T>&>(input).value().image;
      return image ? py::cast(ImageRef{image}) : py::none();
    };
    ops.emit = [](const OutputBase& output, const py::handle& value) {
      static_cast<const runtime::Output<T>&>(output).Emit(
          ImageMessage{ImageFromPython(value, "output '" + output.name() + "'")});
    };
  } else {
    ops.read = [](const InputBase& input) -> py::object {
      return JsonToPython(
          runtime::MessageTraits<T>::ToJson(static_cast<const runtime::Input<T>&>(input).value()));
    };
    ops.emit = [](const OutputBase& output, const py::handle& value) {
      const std::string what = "output '" + output.name() + "'";
      T message;
      try {
        message = runtime::MessageTraits<T>::FromJson(JsonFromPython(value, what));
      } catch (const std::exception& error) {
        throw InvalidArgument(what + ": not a " + runtime::MessageTraits<T>::kName + ": " +
                              error.what());
      }
      static_cast<const runtime::Output<T>&>(output).Emit(message);
    };
  }
  return ops;
}

std::map<std::string, PortOps>& PortTable() {
  static std::map<std::string, PortOps> table = [] {
    std::map<std::string, PortOps> t;
    const auto add = [&t]<runtime::Message T>(T*) {
      t[runtime::MessageTraits<T>::kName] = MakePortOps<T>();
    };
    add(static_cast<runtime::Tick*>(nullptr));
    add(static_cast<runtime::Value*>(nullptr));
    add(static_cast<runtime::Text*>(nullptr));
    add(static_cast<runtime::Empty*>(nullptr));
    add(static_cast<ImageMessage*>(nullptr));
    add(static_cast<components::JointStateMessage*>(nullptr));
    add(static_cast<components::JointCommand*>(nullptr));
    add(static_cast<components::HeadStatusMessage*>(nullptr));
    add(static_cast<components::FacesMessage*>(nullptr));
    add(static_cast<components::CandidatesMessage*>(nullptr));
    add(static_cast<components::SelectionMessage*>(nullptr));
    add(static_cast<components::TrackMessage*>(nullptr));
    add(static_cast<components::TargetMessage*>(nullptr));
    return t;
  }();
  return table;
}

// The latest message of one output, kept in C++ (slots run with the GIL released).
struct Tap {
  std::shared_ptr<const Image> image;  // runtime.image outputs
  nlohmann::json json;                 // every other type
  int64_t count = 0;
};

// A built pipeline, stepped from Python.
class PyPipeline {
 public:
  explicit PyPipeline(runtime::Pipeline pipeline) : pipeline_(std::move(pipeline)) {}
  ~PyPipeline() {
    try {
      Close();
    } catch (...) {
      // Stop's failures are not the destructor's to report; close() raises them.
    }
  }

  runtime::Pipeline& pipeline() { return pipeline_; }
  int64_t steps_done() const { return stepper_.steps_done(); }

  // runtime::Stepper's steps (scheduler.h), on simulated time; the first failure raised.
  void Step(int64_t count) {
    if (closed_) throw Error("Pipeline.step: the pipeline is closed");
    if (count < 0)
      throw InvalidArgument("Pipeline.step: count must be >= 0, got " + std::to_string(count));
    py::gil_scoped_release release;
    if (!started_) Start();
    for (int64_t n = 0; n < count; ++n) {
      const runtime::StepResult& result = stepper_.Step();
      if (!result.errors.empty()) throw Error(result.errors.front().ToString());
    }
  }

  void Close() {
    if (!started_ || closed_) {
      closed_ = true;
      return;
    }
    closed_ = true;
    py::gil_scoped_release release;
    std::string errors;
    for (const runtime::StepError& error : stepper_.Stop()) {
      errors += fmt::format("{}component '{}' failed to stop: {}", errors.empty() ? "" : "; ",
                            error.component, error.message);
    }
    if (!errors.empty()) throw Error(errors);
  }

  Tap& Watch(const std::string& signal) {
    const auto found = taps_.find(signal);
    if (found != taps_.end()) return *found->second;
    const auto dot = signal.find('.');
    Component* component =
        dot == std::string::npos ? nullptr : pipeline_.Find(signal.substr(0, dot));
    if (component == nullptr) {
      throw InvalidArgument(
          "Pipeline: signal '" + signal +
          "': expected <component>.<output> of this pipeline; components: " + ComponentNames());
    }
    OutputBase* output = component->FindOutput(signal.substr(dot + 1));
    if (output == nullptr) {
      std::string known;
      for (const auto& o : component->outputs()) known += (known.empty() ? "" : ", ") + o->name();
      throw InvalidArgument("Pipeline: signal '" + signal + "': component '" + component->name() +
                            "' has no output '" + signal.substr(dot + 1) +
                            "'; its outputs: " + (known.empty() ? "none" : known));
    }
    auto tap = std::make_shared<Tap>();
    if (auto* images = dynamic_cast<runtime::Output<ImageMessage>*>(output)) {
      images->signal().Connect([tap](const ImageMessage& m) {
        tap->image = m.image;
        ++tap->count;
      });
    } else {
      output->ConnectJson([tap](const nlohmann::json& json) {
        tap->json = json;
        ++tap->count;
      });
    }
    taps_.emplace(signal, tap);
    return *tap;
  }

  std::string ComponentNames() const {
    std::string names;
    for (const auto& c : pipeline_.components()) names += (names.empty() ? "" : ", ") + c->name();
    return names;
  }

  Component& Get(const std::string& name) const {
    Component* component = pipeline_.Find(name);
    if (component == nullptr) {
      throw InvalidArgument("Pipeline: no component '" + name +
                            "'; components: " + ComponentNames());
    }
    return *component;
  }

 private:
  static runtime::StepperOptions SimulatedTime() {
    runtime::StepperOptions options;
    options.simulated_time = true;
    return options;
  }

  void Start() {
    if (const std::optional<runtime::StepError> failure = stepper_.Start()) {
      stepper_.Stop();  // those that started; the start failure is the one reported
      closed_ = true;
      throw Error(
          fmt::format("component '{}' failed to start: {}", failure->component, failure->message));
    }
    started_ = true;
  }

  runtime::Pipeline pipeline_;
  // Python paces the steps: the simulated clock's times whatever the file's clock.
  runtime::Stepper stepper_{pipeline_, SimulatedTime()};
  std::map<std::string, std::shared_ptr<Tap>> taps_;
  bool started_ = false;
  bool closed_ = false;
};

py::object TapValue(const Tap& tap) {
  if (tap.count == 0) return py::none();
  if (tap.image) return py::cast(ImageRef{tap.image});
  return JsonToPython(tap.json);
}

// Components written in Python, and the types pipelines may name.
void BindComponentTypes(py::module_& m) {
  m.def(
      "register_component",
      [](const std::string& type, py::function callable, const std::string& description) {
        // Kept for the life of the process, as the registration: never released after the
        // interpreter has ended.
        const py::object* factory = new py::object(std::move(callable));
        runtime::ComponentRegistry::Global().Register(
            type,
            [factory, type]() -> std::unique_ptr<Component> {
              py::gil_scoped_acquire gil;
              py::object impl;
              try {
                impl = (*factory)();
              } catch (py::error_already_set& error) {
                throw Error("making a '" + type + "': " + std::string(error.what()));
              }
              return std::make_unique<PyComponent>(std::move(impl));
            },
            description);
      },
      "type"_a, "factory"_a, "description"_a = "",
      "Registers a component written in Python under `type` (e.g. 'py.gain'), for pipeline "
      "files to name. `factory()` returns an object with `inputs` and `outputs` ({port: message "
      "type}) and `step(context, inputs) -> {output: message}` (saccade.Component documents "
      "it). Raises InvalidArgument when the type is taken.");
  m.def(
      "component_types", [] { return runtime::ComponentRegistry::Global().Types(); },
      "The component types pipeline files can name, sorted.");
  m.def(
      "message_types",
      [] {
        std::vector<std::string> names;
        for (const auto& [name, ops] : PortTable()) names.push_back(name);
        return names;
      },
      "The message types a Python component's ports may have.");
}

// Pipeline's components and signals: what they declare, their latest messages, their methods,
// switching them on and off.
void BindPipelineComponents(py::class_<PyPipeline>& pipeline) {
  pipeline
      .def(
          "describe",
          [](PyPipeline& p, const std::string& name) {
            Component& c = p.Get(name);
            py::dict inputs, outputs, methods;
            for (const auto& i : c.inputs()) inputs[py::str(i->name())] = i->message_type();
            for (const auto& o : c.outputs()) outputs[py::str(o->name())] = o->message_type();
            for (const auto& me : c.methods()) {
              methods[py::str(me->name())] =
                  py::make_tuple(me->request_type(), me->reply_type(), me->description());
            }
            return py::dict("inputs"_a = inputs, "outputs"_a = outputs, "methods"_a = methods,
                            "enabled"_a = c.enabled());
          },
          "component"_a,
          "{'inputs': {port: type}, 'outputs': {port: type}, 'methods': {name: (request, "
          "reply, doc)}, 'enabled': bool}.")
      .def(
          "watch", [](PyPipeline& p, const std::string& signal) { p.Watch(signal); }, "signal"_a,
          "Starts keeping the latest message of '<component>.<output>' (read() does it too).")
      .def(
          "read",
          [](PyPipeline& p, const std::string& signal) { return TapValue(p.Watch(signal)); },
          "signal"_a,
          "The latest message of '<component>.<output>' since it is watched: a saccade.Image "
          "for images (no copy), a dict (its JSON form) for other messages, None before the "
          "first. The first read() starts watching.")
      .def(
          "count", [](PyPipeline& p, const std::string& signal) { return p.Watch(signal).count; },
          "signal"_a, "Messages seen on the signal since it is watched.")
      .def(
          "call",
          [](PyPipeline& p, const std::string& component, const std::string& method,
             py::object request) {
            const nlohmann::json json =
                JsonFromPython(request, component + "." + method + " request");
            nlohmann::json reply;
            {
              py::gil_scoped_release release;
              reply = p.pipeline().Call(component, method,
                                        json.is_null() ? nlohmann::json::object() : json);
            }
            return JsonToPython(reply);
          },
          "component"_a, "method"_a, "request"_a = py::none(),
          "Calls a component's method with a request dict (its JSON form) and returns the "
          "reply dict. Raises saccade.Error naming what is unknown or malformed.")
      .def(
          "set_enabled",
          [](PyPipeline& p, const std::string& name, bool enabled) {
            p.Get(name).SetEnabled(enabled);
          },
          "component"_a, "enabled"_a, "A disabled component is not stepped and emits nothing.")
      .def(
          "python_component",
          [](PyPipeline& p, const std::string& name) -> py::object {
            auto* component = dynamic_cast<PyComponent*>(&p.Get(name));
            return component ? component->impl() : py::none();
          },
          "component"_a, "The Python object behind a Python component, or None.");
}

// Pipeline: building, stepping, closing, what it is made of.
void BindPipeline(py::module_& m) {
  py::class_<PyPipeline> pipeline(
      m, "Pipeline",
      "A pipeline built from a YAML file (include/saccade/runtime/pipeline.h "
      "documents the format), stepped from Python. Use as a context manager "
      "or call close() to stop its components.");
  pipeline
      .def_static(
          "load",
          [](const std::string& path, const std::string& hardware) {
            return std::make_unique<PyPipeline>(runtime::Pipeline::Build(
                runtime::LoadPipelineFile(path, hardware), runtime::ComponentRegistry::Global()));
          },
          "path"_a, "hardware"_a = "",
          "Builds a pipeline file; `hardware` (a hardware file) replaces the file's own "
          "`hardware:` line. Raises FileError with file:line: key.")
      .def_static(
          "from_yaml_string",
          [](const std::string& text, const std::string& source, const std::string& hardware) {
            return std::make_unique<PyPipeline>(
                runtime::Pipeline::Build(runtime::ParsePipeline(text, source, hardware),
                                         runtime::ComponentRegistry::Global()));
          },
          "text"_a, "source"_a = "<string>", "hardware"_a = "",
          "Builds a pipeline from YAML text (relative paths resolve against the current folder).")
      .def("step", &PyPipeline::Step, "count"_a = 1,
           "Runs `count` steps (starting the components before the first): the scheduler's "
           "step, on simulated time whatever the file's clock. Releases the GIL. Raises "
           "saccade.Error naming the component and step when one fails.")
      .def("close", &PyPipeline::Close, "Stops every component (once).")
      .def(
          "__enter__", [](PyPipeline& p) -> PyPipeline& { return p; },
          py::return_value_policy::reference)
      .def("__exit__", [](PyPipeline& p, py::args) { p.Close(); })
      .def_property_readonly("steps_done", &PyPipeline::steps_done)
      .def_property_readonly("dt", [](PyPipeline& p) { return p.pipeline().spec().clock.step; })
      .def_property_readonly(
          "hardware_file", [](PyPipeline& p) { return p.pipeline().spec().hardware_file; },
          "The hardware file used ('' when none).")
      .def_property_readonly(
          "components",
          [](PyPipeline& p) {
            std::vector<std::string> names;
            for (const auto& c : p.pipeline().components()) names.push_back(c->name());
            return names;
          },
          "Component names in execution order.");
  BindPipelineComponents(pipeline);
}

}  // namespace

void BindRuntime(py::module_& m) {
  components::RegisterComponents(runtime::ComponentRegistry::Global());
  // Pipeline connections that name a topic go over DDS, as under `saccade run` (docs/dds.md).
  dds::RegisterDdsTransport(runtime::ComponentRegistry::Global());
  BindComponentTypes(m);
  BindPipeline(m);
}

}  // namespace saccade::python
