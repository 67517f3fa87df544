#include "saccade/runtime/component_registry.h"

#include <algorithm>

namespace saccade::runtime {

ComponentRegistry& ComponentRegistry::Global() {
  static ComponentRegistry registry;
  return registry;
}

void ComponentRegistry::Register(const std::string& type, Factory factory,
                                 std::string description) {
  if (type.empty()) throw InvalidArgument("ComponentRegistry::Register: empty type name");
  if (!factory) {
    throw InvalidArgument("ComponentRegistry::Register: type '" + type + "': empty factory");
  }
  const auto it =
      std::lower_bound(entries_.begin(), entries_.end(), type,
                       [](const auto& entry, const std::string& t) { return entry.first < t; });
  if (it != entries_.end() && it->first == type) {
    throw InvalidArgument("ComponentRegistry::Register: type '" + type + "' is already registered");
  }
  entries_.insert(it, {type, Entry{std::move(factory), std::move(description)}});
}

void ComponentRegistry::RegisterResource(const std::string& kind, ResourceLoader loader) {
  if (kind.empty() || !loader.load) {
    throw InvalidArgument("ComponentRegistry::RegisterResource: empty kind or loader");
  }
  if (!resources_.emplace(kind, std::move(loader)).second) {
    throw InvalidArgument("ComponentRegistry::RegisterResource: resource '" + kind +
                          "' is already registered");
  }
}

void ComponentRegistry::ReplaceResource(const std::string& kind, ResourceLoader loader) {
  const auto it = resources_.find(kind);
  if (it == resources_.end() || !loader.load) {
    throw InvalidArgument("ComponentRegistry::ReplaceResource: resource '" + kind +
                          "' is not registered, or the loader is empty");
  }
  it->second = std::move(loader);
}

bool ComponentRegistry::Has(const std::string& type) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const auto& entry) { return entry.first == type; });
}

std::unique_ptr<Component> ComponentRegistry::Create(const std::string& type) const {
  for (const auto& [name, entry] : entries_) {
    if (name == type) {
      std::unique_ptr<Component> component = entry.factory();
      SACCADE_ASSERT(component != nullptr, "component factory returned null for " + type);
      return component;
    }
  }
  std::string known;
  for (const auto& [name, entry] : entries_) known += (known.empty() ? "" : ", ") + name;
  throw InvalidArgument("unknown component type '" + type +
                        "'; known types: " + (known.empty() ? "(none registered)" : known));
}

std::vector<std::string> ComponentRegistry::Types() const {
  std::vector<std::string> types;
  for (const auto& [name, entry] : entries_) types.push_back(name);
  return types;
}

std::string ComponentRegistry::Description(const std::string& type) const {
  for (const auto& [name, entry] : entries_) {
    if (name == type) return entry.description;
  }
  return {};
}

}  // namespace saccade::runtime
