#pragma once
// The component types a pipeline file can name ("vision.face_detector"), each with a factory.

#include <concepts>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "saccade/runtime/component.h"
#include "saccade/runtime/resources.h"

namespace saccade::runtime {

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
  bool HasResource(const std::string& kind) const { return resources_.contains(kind); }
  const std::map<std::string, ResourceLoader>& resource_loaders() const { return resources_; }

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
};

}  // namespace saccade::runtime
