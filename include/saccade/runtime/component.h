#pragma once
// Components: the units a pipeline runs in order, with a lifecycle and typed ports.
//
// Lifecycle, driven by the pipeline and the scheduler:
//   constructor (declare fixed ports) -> Configure(params) (may declare more ports)
//   -> Start() -> Step(context) once per tick, in pipeline order -> Stop().
// Stop() is called on every component whose Start() returned, also after an error.
//
// Ports are declared with AddInput<T> / AddOutput<T> (port.h); component_registry.h makes
// components by type name.

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "saccade/runtime/message.h"
#include "saccade/runtime/port.h"

namespace saccade::runtime {

/// What a component knows about the current tick.
struct StepContext {
  int64_t step = 0;   ///< 0, 1, 2, ...
  double time = 0.0;  ///< s: step * dt when simulated, wall time since start in real time
  double dt = 0.0;    ///< s: the nominal step (1 / rate_hz in real time)
  uint64_t seed = 0;  ///< this component's seed: f(pipeline seed, component name), constant
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

  /// Reads the parameters (the pipeline file's `params`, {} when absent). Throws
  /// saccade::Error naming the parameter on bad values; the loader adds file and line.
  virtual void Configure(const nlohmann::json& params) { (void)params; }
  /// Acquires resources; called once before the first Step.
  virtual void Start() {}
  /// One tick. May throw: the scheduler reports the component, the step and the message.
  virtual void Step(const StepContext& context) = 0;
  /// Releases resources; called once after the last Step (also after an error).
  virtual void Stop() {}

  /// nullptr when there is no such port.
  InputBase* FindInput(const std::string& name) const;
  OutputBase* FindOutput(const std::string& name) const;
  const std::vector<std::unique_ptr<InputBase>>& inputs() const { return inputs_; }
  const std::vector<std::unique_ptr<OutputBase>>& outputs() const { return outputs_; }

  /// Sets the name, the seed and the folder that relative paths in the params resolve
  /// against (the pipeline file's); the pipeline calls this before Configure.
  void Initialise(std::string name, uint64_t seed, std::string base_dir = {}) {
    name_ = std::move(name);
    seed_ = seed;
    base_dir_ = std::move(base_dir);
  }

  /// `path` as given when absolute or when there is no base folder; else relative to the
  /// pipeline file's folder.
  std::string ResolvePath(const std::string& path) const;

 protected:
  /// Declares an output. Throws InvalidArgument when the name is taken or not an identifier.
  template <Message T>
  Output<T>& AddOutput(const std::string& name) {
    CheckNewPort(name, /*input=*/false);
    auto port = std::make_unique<Output<T>>(name);
    Output<T>& ref = *port;
    outputs_.push_back(std::move(port));
    return ref;
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

  std::string name_;
  uint64_t seed_ = 0;
  std::string base_dir_;
  std::vector<std::unique_ptr<InputBase>> inputs_;
  std::vector<std::unique_ptr<OutputBase>> outputs_;
};

}  // namespace saccade::runtime
