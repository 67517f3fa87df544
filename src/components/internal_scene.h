#pragma once
// The scene a component works in: the pipeline's (`scene:` at the top of the pipeline or
// hardware file; runtime/resources.h), or the file of the component's own `scene` parameter
// where it has one. Either is loaded once for the whole pipeline.
#include <memory>
#include <string>

#include "saccade/runtime/component.h"
#include "saccade/runtime/component_registry.h"
#include "saccade/scene/scene.h"

namespace saccade::components::internal {

struct SceneRef {
  std::shared_ptr<const scene::Scene> scene;
  std::string path;  ///< its file, for messages
};

/// The documentation of the `scene` parameter, the same in every component that has one.
inline constexpr const char* kSceneParamDoc =
    "the scene (its robot is the head); the pipeline's `scene:` when not given";

/// The scene of the component's `scene` parameter (`scene_param`, relative to the pipeline
/// file) when given, else the pipeline's. Throws InvalidArgument when neither names a scene;
/// the scene loader's FileError passes through.
SceneRef SceneOf(runtime::Component& component, const std::string& scene_param);

/// The scene's robot; throws InvalidArgument naming the file when it has none.
const scene::Robot& RobotOf(const scene::Scene& scene, const std::string& path);

/// Makes "scene" a resource kind of `registry` (scene::Scene::Load), once.
void RegisterSceneResource(runtime::ComponentRegistry& registry);

}  // namespace saccade::components::internal
