#pragma once
// The scene a component works in: the pipeline's (`scene:` at the top of the pipeline or
// hardware file; runtime/resources.h), or the file of the component's own `scene` parameter
// where it has one. Either is loaded once for the whole pipeline.
#include <memory>
#include <string>

#include "components/internal_params.h"
#include "saccade/runtime/component.h"
#include "saccade/runtime/component_registry.h"
#include "saccade/scene/scene.h"

namespace saccade::components::internal {

struct SceneRef {
  std::shared_ptr<const scene::Scene> scene;
  std::string path;  ///< its file, for messages
};

/// Reads the optional parameter `scene` from `p`. Throws InvalidArgument when neither the
/// parameter nor the pipeline names a scene; the scene loader's FileError passes through.
SceneRef SceneOf(runtime::Component& component, Params& p);

/// The scene's robot; throws InvalidArgument naming the file when it has none.
const scene::Robot& RobotOf(const scene::Scene& scene, const std::string& path);

/// Makes "scene" a resource kind of `registry` (scene::Scene::Load), once.
void RegisterSceneResource(runtime::ComponentRegistry& registry);

}  // namespace saccade::components::internal
