#pragma once
// A pipeline's shared resources: files that several components need (the scene, and with it
// the robot) are named once in the pipeline (or hardware) file, loaded once by the pipeline
// and handed to every component that asks, typed. The pipeline owns them; there is no static
// cache. runtime knows no scene: the layer that knows a kind registers how to load it
// (ComponentRegistry::RegisterResource; components registers "scene").
//
//   scene: ../scenes/portraits.yaml      # top level of a pipeline file, or of its hardware
//                                        # file (which then wins), relative to that file
//
// A component gets the pipeline's scene with `resources().Default<scene::Scene>("scene")`,
// or another file of the same kind with `resources().Load<scene::Scene>("scene", path)`
// (loaded once per canonical path for the whole pipeline).
//
// Thread-safety: components configure on one thread; Resources is not synchronised.
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <typeindex>
#include <utility>

#include "saccade/core/error.h"

namespace saccade::runtime {

/// How to load one kind of resource from a file, with the C++ type it gives.
struct ResourceLoader {
  std::type_index type = typeid(void);
  std::string type_name;  ///< for messages ("scene::Scene")
  std::function<std::shared_ptr<const void>(const std::string& path)> load;
};

class Resources {
 public:
  /// The kinds this pipeline can load (from its registry).
  explicit Resources(std::map<std::string, ResourceLoader> loaders = {})
      : loaders_(std::move(loaders)) {}

  /// The pipeline's own resource of `kind` is the file at `path` (absolute, or relative to the
  /// current folder). Throws InvalidArgument for a kind without a loader.
  void SetDefault(const std::string& kind, const std::string& path);
  /// The path SetDefault gave for `kind`; nullopt when none.
  std::optional<std::string> DefaultPath(const std::string& kind) const;

  /// The resource of `kind` at `path`, loaded at the first call for its canonical path and
  /// shared afterwards. Throws InvalidArgument for an unknown kind or a T other than the
  /// loader's; the loader's own errors (FileError naming the file) pass through.
  template <typename T>
  std::shared_ptr<const T> Load(const std::string& kind, const std::string& path) {
    return std::static_pointer_cast<const T>(LoadErased(kind, path, typeid(T)));
  }
  /// Loads the pipeline's resource of `kind` now (the pipeline does, so that a bad file is
  /// reported at its line before any component is built). Throws as Load.
  void LoadDefault(const std::string& kind);
  /// The pipeline's resource of `kind` (SetDefault); nullptr when the pipeline names none.
  template <typename T>
  std::shared_ptr<const T> Default(const std::string& kind) {
    const std::optional<std::string> path = DefaultPath(kind);
    return path ? Load<T>(kind, *path) : nullptr;
  }

 private:
  std::shared_ptr<const void> LoadErased(const std::string& kind, const std::string& path,
                                         std::type_index type);

  std::map<std::string, ResourceLoader> loaders_;
  std::map<std::string, std::string> defaults_;                // kind -> path
  std::map<std::string, std::shared_ptr<const void>> loaded_;  // kind + '\n' + canonical path
};

}  // namespace saccade::runtime
