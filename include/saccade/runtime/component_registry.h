#pragma once
// The component types a pipeline file can name ("vision.face_detector"), each with a factory.

#include <concepts>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "saccade/runtime/component.h"

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
};

}  // namespace saccade::runtime
