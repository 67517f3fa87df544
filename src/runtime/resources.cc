#include "saccade/runtime/resources.h"

#include <fmt/format.h>

#include <filesystem>
#include <system_error>

namespace saccade::runtime {

void Resources::SetDefault(const std::string& kind, const std::string& path) {
  if (!loaders_.contains(kind)) {
    throw InvalidArgument(
        fmt::format("no resource of kind '{}' can be loaded here (the pipeline's "
                    "registry has no loader for it)",
                    kind));
  }
  defaults_[kind] = path;
}

std::optional<std::string> Resources::DefaultPath(const std::string& kind) const {
  const auto it = defaults_.find(kind);
  if (it == defaults_.end()) return std::nullopt;
  return it->second;
}

void Resources::LoadDefault(const std::string& kind) {
  const std::optional<std::string> path = DefaultPath(kind);
  if (path) LoadErased(kind, *path, loaders_.at(kind).type);
}

std::shared_ptr<const void> Resources::LoadErased(const std::string& kind, const std::string& path,
                                                  std::type_index type) {
  const auto loader = loaders_.find(kind);
  if (loader == loaders_.end()) {
    throw InvalidArgument(fmt::format("no resource of kind '{}' can be loaded here", kind));
  }
  if (loader->second.type != type) {
    throw InvalidArgument(fmt::format("resource '{}' is a {}, asked for another type", kind,
                                      loader->second.type_name));
  }
  std::error_code ec;
  std::string key = std::filesystem::weakly_canonical(path, ec).string();
  if (ec) key = path;
  key = kind + '\n' + key;
  if (const auto it = loaded_.find(key); it != loaded_.end()) return it->second;
  std::shared_ptr<const void> resource = loader->second.load(path);
  loaded_.emplace(key, resource);
  return resource;
}

}  // namespace saccade::runtime
