#pragma once
// Components: the units a pipeline runs in order, with a lifecycle and typed ports.
//
// Lifecycle, driven by the pipeline and the scheduler:
//   constructor (declare fixed ports and the parameters) -> Configure(params) (may declare
//   more ports) -> Start() -> Step(context) once per tick, in pipeline order -> Stop().
// Parameters are declared once with DeclareParam (params.h); the default Configure applies
// the pipeline file's `params` to them, then calls Configured() for what follows from them.
// Stop() is called on every component whose Start() returned, also after an error.
//
// Ports are declared with AddInput<T> / AddOutput<T> (port.h); methods (seed section 5.4:
// one-to-one requests with a reply or an error) with AddMethod<Request, Reply>, callable in
// the process by type (FindMethod) or by name with JSON (Pipeline::Call, for text links).
// component_registry.h makes components by type name.

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "saccade/runtime/bus.h"
#include "saccade/runtime/message.h"
#include "saccade/runtime/params.h"
#include "saccade/runtime/port.h"
#include "saccade/runtime/resources.h"

namespace saccade::runtime {

/// What a component knows about the current tick.
struct StepContext {
  int64_t step = 0;   ///< 0, 1, 2, ...
  double time = 0.0;  ///< s: step * dt when simulated, wall time since start in real time
  double dt = 0.0;    ///< s: the nominal step (1 / rate_hz in real time)
  uint64_t seed = 0;  ///< this component's seed: f(pipeline seed, component name), constant
  /// The wall clock runs the loop (clock mode realtime, or a live run paced from outside, as
  /// the GUI's: RunOptions::live): work may finish when it does. When false, a component that
  /// models a latency must keep to it, for runs to be repeatable.
  bool realtime = false;
  /// A component that blocks on a device (sim.cameras waiting for its frames) calls this now
  /// and then while it waits, on its own thread: RunOptions::while_waiting, for the run's owner
  /// to do its work meanwhile (a live GUI takes commands). Set only where nothing else runs at
  /// the time (a level stepped one component after the other); null otherwise.
  const std::function<void()>* while_waiting = nullptr;
};

/// A component's method without its types: name, message types, and a JSON call.
class MethodBase {
 public:
  MethodBase(std::string name, std::string request_type, std::string reply_type,
             std::string description)
      : name_(std::move(name)),
        request_type_(std::move(request_type)),
        reply_type_(std::move(reply_type)),
        description_(std::move(description)) {}
  virtual ~MethodBase() = default;
  const std::string& name() const { return name_; }
  const std::string& request_type() const { return request_type_; }
  const std::string& reply_type() const { return reply_type_; }
  const std::string& description() const { return description_; }
  /// Converts the request from JSON, calls, and returns the reply as JSON. Throws MethodError
  /// (naming the method) for a malformed request or a failing handler.
  virtual nlohmann::json CallJson(const nlohmann::json& request) const = 0;

 private:
  std::string name_, request_type_, reply_type_, description_;
};

/// A typed method of a component (bus.h's Method with its JSON adapter).
template <Message Request, Message Reply>
class ComponentMethod final : public MethodBase {
 public:
  ComponentMethod(const std::string& name, std::string description)
      : MethodBase(name, MessageName<Request>(), MessageName<Reply>(), std::move(description)),
        method_(name) {}
  Method<Request, Reply>& method() { return method_; }
  const Method<Request, Reply>& method() const { return method_; }
  nlohmann::json CallJson(const nlohmann::json& json) const override {
    Request request;
    try {
      request = MessageTraits<Request>::FromJson(json);
    } catch (const std::exception& error) {
      throw MethodError(name(), std::string("bad request: ") + error.what());
    }
    return MessageTraits<Reply>::ToJson(method_.Call(request));
  }

 private:
  Method<Request, Reply> method_;
};

/// Base of every pipeline component. Subclasses declare ports with AddInput / AddOutput in
/// their constructor or Configure, and implement Step.
class Component {
 public:
  Component() = default;
  virtual ~Component() = default;
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;

  /// The component's name in its pipeline ("detector").
  const std::string& name() const { return name_; }
  /// This component's seed (see StepContext::seed); set before Configure.
  uint64_t seed() const { return seed_; }

  /// Reads the parameters (the pipeline file's `params`, null when absent). Throws
  /// saccade::Error naming the parameter on bad values; the loader adds file and line. The
  /// default applies `params` to the declared parameters, then calls Configured().
  virtual void Configure(const nlohmann::json& params);
  /// The declared parameters (params.h).
  const ParamTable& param_table() const { return params_; }
  /// Acquires resources; called once before the first Step.
  virtual void Start() {}
  /// One tick. May throw: the scheduler reports the component, the step and the message.
  virtual void Step(const StepContext& context) = 0;
  /// Releases resources; called once after the last Step (also after an error).
  virtual void Stop() {}
  /// Whether Step must run on the thread that runs the pipeline (it owns an OpenGL context,
  /// say). Other components may be stepped on the scheduler's threads, beside the components
  /// of their level (scheduler.h); they must not share mutable state with those.
  virtual bool thread_affine() const { return false; }

  /// A disabled component is not stepped (the scheduler skips it and marks its inputs seen),
  /// so it emits nothing: the GUI switches the perception part of a loop off this way. Set
  /// it between steps, from the thread that runs the pipeline. Enabled by default.
  void SetEnabled(bool enabled) { enabled_ = enabled; }
  bool enabled() const { return enabled_; }

  /// nullptr when there is no such port.
  InputBase* FindInput(const std::string& name) const;
  OutputBase* FindOutput(const std::string& name) const;
  const std::vector<std::unique_ptr<InputBase>>& inputs() const { return inputs_; }
  const std::vector<std::unique_ptr<OutputBase>>& outputs() const { return outputs_; }
  const std::vector<std::unique_ptr<MethodBase>>& methods() const { return methods_; }
  /// nullptr when there is no such method.
  const MethodBase* FindMethod(const std::string& name) const;
  /// The typed method, for callers in the process; nullptr when absent or of other types.
  template <Message Request, Message Reply>
  const Method<Request, Reply>* FindMethod(const std::string& name) const {
    const auto* typed = dynamic_cast<const ComponentMethod<Request, Reply>*>(FindMethod(name));
    return typed ? &typed->method() : nullptr;
  }

  /// Sets the name, the seed, the folder that relative paths in the params resolve against
  /// (the pipeline file's) and the pipeline's shared resources; the pipeline calls this
  /// before Configure.
  void Initialise(std::string name, uint64_t seed, std::string base_dir = {},
                  std::shared_ptr<Resources> resources = nullptr) {
    name_ = std::move(name);
    seed_ = seed;
    base_dir_ = std::move(base_dir);
    resources_ = std::move(resources);
  }

  /// The pipeline's shared resources (resources.h). A component made outside a pipeline gets
  /// resources of its own, with the loaders of ComponentRegistry::Global() and no defaults.
  Resources& resources();

  /// `path` as given when absolute or when there is no base folder; else relative to the
  /// pipeline file's folder.
  std::string ResolvePath(const std::string& path) const;

 protected:
  /// Declares the parameter `name`, which sets `*member` (see params.h); the member's current
  /// value is its default. Call it from the constructor.
  template <typename T>
  ParamDecl DeclareParam(const std::string& name, T* member, std::string doc) {
    return params_.Declare(name, member, std::move(doc));
  }
  /// Called by the default Configure once the declared members are set: check combinations,
  /// load resources, declare ports that depend on the parameters. Throws like Configure.
  virtual void Configured() {}

  /// Declares an output. Throws InvalidArgument when the name is taken or not an identifier.
  template <Message T>
  Output<T>& AddOutput(const std::string& name) {
    CheckNewPort(name, /*input=*/false);
    auto port = std::make_unique<Output<T>>(name);
    Output<T>& ref = *port;
    outputs_.push_back(std::move(port));
    return ref;
  }

  /// Declares a method served by `handler` (one-to-one; a throwing handler becomes a
  /// MethodError for the caller). Throws InvalidArgument when the name is taken or not an
  /// identifier.
  template <Message Request, Message Reply>
  void AddMethod(const std::string& name, std::function<Reply(const Request&)> handler,
                 std::string description) {
    CheckNewMethod(name);
    auto method = std::make_unique<ComponentMethod<Request, Reply>>(name, std::move(description));
    method->method().Bind(std::move(handler));
    methods_.push_back(std::move(method));
  }

  /// Declares an input; a `required` input must be connected in the pipeline file.
  template <Message T>
  Input<T>& AddInput(const std::string& name, bool required = false) {
    CheckNewPort(name, /*input=*/true);
    auto port = std::make_unique<Input<T>>(name, required);
    Input<T>& ref = *port;
    inputs_.push_back(std::move(port));
    return ref;
  }

 private:
  void CheckNewPort(const std::string& name, bool input) const;
  void CheckNewMethod(const std::string& name) const;

  std::string name_;
  uint64_t seed_ = 0;
  std::string base_dir_;
  std::shared_ptr<Resources> resources_;
  bool enabled_ = true;
  ParamTable params_;
  std::vector<std::unique_ptr<InputBase>> inputs_;
  std::vector<std::unique_ptr<OutputBase>> outputs_;
  std::vector<std::unique_ptr<MethodBase>> methods_;
};

/// A component that gives its pipeline the time of each step from what it receives: a topic
/// reader, from the sender's capture stamps (`clock.source`, pipeline.h). Before each step of
/// the simulated clock the scheduler asks it; it takes the step's message then (waiting as its
/// options say) and emits that message in Step.
class TimeSource {
 public:
  virtual ~TimeSource() = default;
  /// The stamp, in seconds, of the message this step will emit; nullopt when none came.
  virtual std::optional<double> NextTime() = 0;
};

}  // namespace saccade::runtime
