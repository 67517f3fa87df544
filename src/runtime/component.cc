#include "saccade/runtime/component.h"

#include <algorithm>
#include <filesystem>

#include "saccade/runtime/component_registry.h"

namespace saccade::runtime {
namespace {

bool IsIdentifier(const std::string& name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

}  // namespace

void Component::Configure(const nlohmann::json& params) {
  params_.Apply(params);
  Configured();
}

std::string Component::ResolvePath(const std::string& path) const {
  const std::filesystem::path p(path);
  if (p.is_absolute() || base_dir_.empty() || path.empty()) return path;
  return (std::filesystem::path(base_dir_) / p).lexically_normal().string();
}

Resources& Component::resources() {
  if (!resources_) {
    resources_ = std::make_shared<Resources>(ComponentRegistry::Global().resource_loaders());
  }
  return *resources_;
}

InputBase* Component::FindInput(const std::string& name) const {
  for (const auto& port : inputs_) {
    if (port->name() == name) return port.get();
  }
  return nullptr;
}

OutputBase* Component::FindOutput(const std::string& name) const {
  for (const auto& port : outputs_) {
    if (port->name() == name) return port.get();
  }
  return nullptr;
}

const MethodBase* Component::FindMethod(const std::string& name) const {
  for (const auto& method : methods_) {
    if (method->name() == name) return method.get();
  }
  return nullptr;
}

void Component::CheckNewMethod(const std::string& name) const {
  if (!IsIdentifier(name)) {
    throw InvalidArgument("Component::AddMethod: component '" + name_ + "': method name '" + name +
                          "' must be non-empty letters, digits, '_' or '-'");
  }
  if (FindMethod(name) != nullptr) {
    throw InvalidArgument("Component::AddMethod: component '" + name_ +
                          "' already has a method named '" + name + "'");
  }
}

void Component::CheckNewPort(const std::string& name, bool input) const {
  const char* kind = input ? "AddInput" : "AddOutput";
  if (!IsIdentifier(name)) {
    throw InvalidArgument(std::string("Component::") + kind + ": component '" + name_ +
                          "': port name '" + name +
                          "' must be non-empty letters, digits, '_' or '-'");
  }
  if ((input && FindInput(name) != nullptr) || (!input && FindOutput(name) != nullptr)) {
    throw InvalidArgument(std::string("Component::") + kind + ": component '" + name_ +
                          "' already has a port named '" + name + "'");
  }
}

}  // namespace saccade::runtime
