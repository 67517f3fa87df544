#pragma once
// Pipelines: components in execution order, their parameters and connections, from a YAML
// file (DESIGN.md: swapping simulated for real hardware is a change of that file).
//
//   clock: {mode: simulated, step: 0.04, steps: 500}   # or {mode: realtime, rate_hz: 25}
//   seed: 1                                            # default 0
//   threads: 2                                         # default 0: one per core (below)
//   on_error: stop                                     # or continue; default stop
//   components:                                        # execution order
//     - name: cameras                                  # letters, digits, '_' or '-'
//       type: sim.cameras                              # a ComponentRegistry type
//       params: {...}                                  # free-form, handed to Configure
//     - name: detector
//       type: vision.faces
//       inputs:
//         image: cameras.left                          # <component>.<output>
//         joints: {from: motors.joints, delay: 1}      # delivered at the next step
//
// Relative paths in params (e.g. `calibration: left.yml`) resolve against the pipeline file's
// folder (Component::ResolvePath).
//
// Hardware files: the one line that swaps the simulated robot for the real one (issue 7).
//
//   hardware: ../hardware/simulator.yaml     # relative to the pipeline file
//   components:
//     - name: cameras                        # no type: type and params from the hardware file
//       inputs: {joints: {from: head.joints, delay: 1}}
//
// A hardware file names the components that stand for the robot, with their type and params
// (relative paths in those params resolve against the hardware file's folder):
//
//   scene: ../scenes/portraits.yaml          # the world and its robot (below)
//   components:
//     cameras: {type: sim.cameras, params: {cameras: [left, right]}}
//     head: {type: sim.head}
//
// Shared resources (resources.h): `scene: FILE` at the top of a pipeline file or of its
// hardware file (relative to that file) names the scene once: the pipeline's own line wins
// over the file its `hardware:` line names, and a hardware file given in place of that line
// (ParsePipeline's `hardware`, `--hardware`) wins over the pipeline's. The pipeline
// loads it before building any component and hands it to those that ask
// (Component::resources()); a component's own `scene` parameter, where it has one, names
// another file of the same kind, loaded once per pipeline as well.
//
// The pipeline keeps the order and the connections; every component without a type must be
// in the hardware file, and every component of the hardware file must be in the pipeline.
// A connection from a later (or the same) component is a cycle unless it has `delay: 1`;
// connections from earlier components are delivered at once. Every error is a FileError
// naming file, line and key.
//
// Topics (issue 16, docs/dds.md): a connection may name a topic of another process instead of
// a component's port, in either direction, so that one pipeline split in two runs as two
// processes. The transport is registered by the layer that has one
// (ComponentRegistry::SetTopicTransport; the dds module registers DDS): runtime knows no DDS.
//
//   transport: {domain: 7, namespace: /saccade}       # handed to the transport as it is
//   components:
//     - name: faces_left
//       type: vision.face_detector
//       inputs:
//         image: {topic: left/image_raw, wait_s: 2}   # read from a topic (options: transport's)
//     - name: fixation
//       type: control.fixation
//       inputs: {target: triangulate.target}
//       outputs:
//         command: head/command                        # or {topic: head/command, qos: default}
//
// A topic input is read by a component the transport makes, stepped just before its reader
// (named "<component>-<input>-topic"); a topic output is written as its component emits.
//
// The receiving half of a split pipeline steps on the sender's clock: `clock.source` names a
// topic input whose messages carry capture stamps (the images), and each simulated step takes
// the time of the message its reader takes for it (scheduler.h) rather than step * step.
//
//   clock: {mode: simulated, step: 0.04, source: faces_left.image}
//
// Parallel steps (scheduler.h): components that do not depend on each other within a step
// (the two eyes' detectors, say) run at the same time on `threads` threads; the run is the
// same, bit for bit, as with `threads: 1`.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "saccade/runtime/component.h"
#include "saccade/runtime/component_registry.h"

namespace saccade::runtime {

/// Components of one pipeline (each is built, configured and stepped in order; a loop of the
/// seed's kind has about ten).
inline constexpr int kMaxComponents = 1000;

enum class ClockMode { kSimulated, kRealtime };
enum class OnError { kStop, kContinue };

/// How time advances.
struct ClockSpec {
  ClockMode mode = ClockMode::kSimulated;
  double step = 0.04;   ///< s, > 0 (simulated)
  double rate_hz = 25;  ///< Hz, > 0 (real time)
  int64_t steps = 0;    ///< steps to run; 0: until RunOptions::stop is set (scheduler.h)
  /// Simulated only: "<component>.<input>", an input that reads a topic; each step's time is
  /// then the stamp of the message its reader takes for the step (Pipeline::time_source), so
  /// a receiving pipeline steps on the sender's capture times. "" : step * `step`.
  std::string source;
  int source_line = 0;  ///< of `source`, in the pipeline file
};

/// One input's connection: `to_input` of the component reads `from_component.from_output`,
/// or, when `topic` is not empty, the topic (the pipeline's topic transport reads it).
struct ConnectionSpec {
  std::string from_component;
  std::string from_output;
  std::string to_input;
  int delay = 0;                                            ///< 0 or 1 step
  int line = 0;                                             ///< in the pipeline file
  std::string topic;                                        ///< "" for a component's port
  nlohmann::json topic_options = nlohmann::json::object();  ///< the entry's other keys
};

/// An output also written to a topic (`outputs: {port: topic}` of a component).
struct TopicOutputSpec {
  std::string output;
  std::string topic;
  nlohmann::json topic_options = nlohmann::json::object();
  int line = 0;
};

struct ComponentSpec {
  std::string name;
  std::string type;
  nlohmann::json params = nlohmann::json::object();
  std::vector<ConnectionSpec> inputs;
  std::vector<TopicOutputSpec> topic_outputs;
  int line = 0;
  int type_line = 0;
  int params_line = 0;
  /// The hardware file that gave the type and params ("" when the pipeline file did): the
  /// lines above are that file's, and relative paths in the params resolve against its folder.
  std::string params_file;
  /// The consumer's component whose topic input this component reads (set by Build for the
  /// readers the topic transport makes, "<consumer>-<input>-topic"); "" for the file's own.
  std::string reads_for;
};

/// A shared resource named at the top of a pipeline or hardware file.
struct ResourceSpec {
  std::string path;  ///< as resolved against its file's folder
  std::string file;  ///< the file that names it, for messages
  int line = 0;
};

/// A parsed (not yet built) pipeline file.
inline constexpr int kMaxThreads = 64;

struct PipelineSpec {
  std::string file;  ///< for messages
  ClockSpec clock;
  uint64_t seed = 0;
  /// Threads that step the components of a level (those that do not depend on each other in
  /// one step) at the same time; 1: one after the other; 0: one per core, at most kMaxThreads.
  /// The results are the same, bit for bit, whatever the number.
  int threads = 0;
  OnError on_error = OnError::kStop;
  std::vector<ComponentSpec> components;
  std::string hardware_file;  ///< the hardware file used ("" when none)
  /// Shared resources by kind ("scene"), from the pipeline file or its hardware file.
  std::map<std::string, ResourceSpec> resources;
  /// The `transport:` map, handed to the topic transport as it is (empty when absent).
  nlohmann::json transport = nlohmann::json::object();
  int transport_line = 0;
};

/// Parses pipeline YAML; checks its shape (keys, types, ranges, duplicate names), and reads
/// its hardware file, if any: `hardware` (a path, relative to the current folder) replaces the
/// file's own `hardware:` line when not empty. Throws FileError ("file:line: key: what").
PipelineSpec ParsePipeline(const std::string& text, const std::string& source,
                           const std::string& hardware = "");
/// Reads and parses a pipeline file (and its hardware file). Throws FileError.
PipelineSpec LoadPipelineFile(const std::string& path, const std::string& hardware = "");

/// Replaces the pipeline's scene resource and every component's own `scene` parameter with
/// `path` (made absolute: the pipeline file's folder is not the caller's); `origin` names
/// where it came from in messages ("--scene"). Throws InvalidArgument when it does not exist.
void ReplaceScene(PipelineSpec& spec, const std::string& path, const std::string& origin);

/// The seed handed to a component: a fixed mix of the pipeline seed and the component's
/// name (the same on every platform and run).
uint64_t ComponentSeed(uint64_t pipeline_seed, const std::string& component_name);

/// Built components, configured and connected, ready to run (see scheduler.h).
class Pipeline {
 public:
  /// Creates each component from `registry`, configures it with its params and connects the
  /// ports. Throws FileError naming file, line and key for: an unknown type (listing the
  /// known ones), bad params (Configure's message), an unknown component or port, ports of
  /// different message types (naming both), a required input left unconnected, and a cycle
  /// (naming its components).
  static Pipeline Build(const PipelineSpec& spec,
                        const ComponentRegistry& registry = ComponentRegistry::Global());
  static Pipeline LoadFile(const std::string& path,
                           const ComponentRegistry& registry = ComponentRegistry::Global());
  static Pipeline LoadString(const std::string& text, const std::string& source,
                             const ComponentRegistry& registry = ComponentRegistry::Global());

  Pipeline(Pipeline&&) noexcept;
  Pipeline& operator=(Pipeline&&) noexcept;
  ~Pipeline();

  const PipelineSpec& spec() const { return spec_; }
  /// The shared resources the components were given (resources.h).
  Resources& resources() const { return *resources_; }
  /// Components in execution order.
  const std::vector<std::unique_ptr<Component>>& components() const { return components_; }
  /// nullptr when there is none of that name.
  Component* Find(const std::string& name) const;
  /// The component `name` as a T; nullptr when absent or of another type.
  template <typename T>
  T* Find(const std::string& name) const {
    return dynamic_cast<T*>(Find(name));
  }

  /// The first component that implements the interface `Role` (the robot's roles:
  /// components/roles.h), with its name; nullptr when none does.
  template <typename Role>
  Role* FindRole(std::string* name = nullptr) const {
    for (const auto& component : components_) {
      if (auto* role = dynamic_cast<Role*>(component.get())) {
        if (name) *name = component->name();
        return role;
      }
    }
    return nullptr;
  }

  /// Calls `component`'s `method` with a JSON request and returns the JSON reply (seed 5.4:
  /// methods are one-to-one with a reply or an error). Call between steps, from the thread
  /// that runs the pipeline. Throws MethodError naming what is unknown (the component, or the
  /// method and the component's methods), a malformed request or a failing handler.
  nlohmann::json Call(const std::string& component, const std::string& method,
                      const nlohmann::json& request) const;

  /// The reader that gives the steps their time (`clock.source`); nullptr when the clock is
  /// step * clock.step.
  TimeSource* time_source() const { return time_source_; }

  /// Hands over messages held back by delayed connections (the scheduler, each step).
  void DeliverDelayed();
  /// Begins a step before its components: the topic transport's start-of-step work (DDS
  /// publishes /clock, docs/dds.md). The scheduler and Python's step call it.
  void BeginStep(const StepContext& context);
  /// Ends a step after its components: the topic writers' end-of-step work (a lockstep
  /// writer marks the step done, docs/dds.md). The scheduler and Python's step call it.
  void EndStep(const StepContext& context);
  /// Seconds spent delivering messages since the last call (and resets the count).
  double TakeDeliverySeconds();

 private:
  Pipeline() = default;

  PipelineSpec spec_;
  std::shared_ptr<Resources> resources_;
  std::vector<std::unique_ptr<Component>> components_;
  TimeSource* time_source_ = nullptr;                                 // one of components_
  std::vector<std::function<void(const StepContext&)>> step_begins_;  // BeginStep's
  std::vector<std::function<void(const StepContext&)>> step_ends_;    // EndStep's, in file order
  // Boxed so that the delivery callbacks' pointer stays valid when the pipeline moves.
  std::unique_ptr<double> delivery_seconds_ = std::make_unique<double>(0.0);
};

}  // namespace saccade::runtime
