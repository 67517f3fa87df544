#pragma once
// The component types a pipeline file can name ("vision.face_detector"), each with a factory.

#include <concepts>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "saccade/runtime/component.h"
#include "saccade/runtime/resources.h"

namespace saccade::runtime {

struct PipelineSpec;

/// One end of a topic connection, as the pipeline hands it to the topic transport.
struct TopicEndpoint {
  std::string topic;         ///< as the file names it (the transport resolves it)
  std::string message_type;  ///< MessageTraits<T>::kName of the port
  nlohmann::json options = nlohmann::json::object();  ///< the connection's other keys
  const PipelineSpec* pipeline = nullptr;             ///< its clock and `transport:` map
  std::string where;                                  ///< "component.port" for messages
};

/// Carries messages between processes on topics (the dds module registers one). Both
/// functions throw saccade::Error naming what is wrong with the endpoint; the pipeline adds
/// the file, line and key.
struct TopicTransport {
  std::string name;  ///< "dds"
  /// A component with one output "message" of the endpoint's type, that emits what the
  /// topic receives each step (configured: the pipeline only names and seeds it).
  std::function<std::unique_ptr<Component>(const TopicEndpoint& endpoint)> make_reader;
  /// Writes every message `output` emits to the topic from now on. Returns what the writer
  /// does at the end of each step, after every component stepped (a lockstep writer marks
  /// the step done), or an empty function.
  std::function<std::function<void(const StepContext&)>(const TopicEndpoint& endpoint,
                                                        OutputBase& output)>
      attach_writer;
  /// Optional. Called once for each pipeline with topic connections, after its readers and
  /// writers: returns what the transport does at the start of each step, before any
  /// component (DDS publishes the simulated clock on /clock), or an empty function. Throws
  /// saccade::Error naming what is wrong with the pipeline's `transport:` map.
  std::function<std::function<void(const StepContext&)>(const PipelineSpec& pipeline)>
      attach_pipeline;
};

/// Makes components by type name ("vision.face_detector"). Modules register theirs.
class ComponentRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Component>()>;

  /// The process-wide registry (empty at first; not thread-safe: register at start-up).
  static ComponentRegistry& Global();

  /// Registers `factory` under `type`. Throws InvalidArgument when `type` is taken or empty.
  void Register(const std::string& type, Factory factory, std::string description = {});
  /// Registers T (default-constructible) under `type`.
  template <std::derived_from<Component> T>
  void Register(const std::string& type, std::string description = {}) {
    Register(
        type, [] { return std::make_unique<T>(); }, std::move(description));
  }

  /// Registers how to load the shared resource `kind` ("scene") named at the top of pipeline
  /// files (resources.h). Throws InvalidArgument when `kind` is taken or empty.
  template <typename T>
  void RegisterResource(const std::string& kind, std::string type_name,
                        std::function<std::shared_ptr<const T>(const std::string& path)> load) {
    RegisterResource(kind, ResourceLoader{typeid(T), std::move(type_name),
                                          [load = std::move(load)](const std::string& path) {
                                            return std::shared_ptr<const void>(load(path));
                                          }});
  }
  void RegisterResource(const std::string& kind, ResourceLoader loader);
  /// Replaces how `kind` loads (a copy of a registry that loads scenes with another head).
  /// Throws InvalidArgument when `kind` is not registered or the loader is empty.
  void ReplaceResource(const std::string& kind, ResourceLoader loader);
  bool HasResource(const std::string& kind) const { return resources_.contains(kind); }
  const std::map<std::string, ResourceLoader>& resource_loaders() const { return resources_; }

  /// Sets the transport that pipelines use for topic connections (a later call replaces it).
  void SetTopicTransport(TopicTransport transport) { topic_transport_ = std::move(transport); }
  /// nullptr when none is set.
  const TopicTransport* topic_transport() const {
    return topic_transport_.make_reader ? &topic_transport_ : nullptr;
  }

  bool Has(const std::string& type) const;
  /// A new component. Throws InvalidArgument naming the known types when `type` is unknown.
  std::unique_ptr<Component> Create(const std::string& type) const;
  /// Registered types, sorted.
  std::vector<std::string> Types() const;
  /// The description given at registration ("" when none or unknown).
  std::string Description(const std::string& type) const;

 private:
  struct Entry {
    Factory factory;
    std::string description;
  };
  std::vector<std::pair<std::string, Entry>> entries_;  // sorted by type
  std::map<std::string, ResourceLoader> resources_;
  TopicTransport topic_transport_;
};

}  // namespace saccade::runtime
