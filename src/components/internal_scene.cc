#include "components/internal_scene.h"

#include "saccade/core/error.h"
#include "saccade/runtime/component_registry.h"

namespace saccade::components::internal {

SceneRef SceneOf(runtime::Component& component, const std::string& scene_param) {
  runtime::Resources& resources = component.resources();
  if (!scene_param.empty()) {
    const std::string path = component.ResolvePath(scene_param);
    return {resources.Load<scene::Scene>("scene", path), path};
  }
  if (const auto path = resources.DefaultPath("scene")) {
    return {resources.Default<scene::Scene>("scene"), *path};
  }
  throw InvalidArgument(
      "no scene: name it once at the top of the pipeline or hardware file (scene: FILE), or "
      "give this component the parameter 'scene'");
}

const scene::Robot& RobotOf(const scene::Scene& scene, const std::string& path) {
  if (!scene.robot()) throw InvalidArgument("scene '" + path + "' has no robot: head");
  return *scene.robot();
}

void RegisterSceneResource(runtime::ComponentRegistry& registry) {
  if (registry.HasResource("scene")) return;
  registry.RegisterResource<scene::Scene>("scene", "scene::Scene", [](const std::string& path) {
    return std::make_shared<const scene::Scene>(scene::Scene::Load(path));
  });
}

}  // namespace saccade::components::internal
