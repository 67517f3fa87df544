#include "saccade/components/scene_cache.h"

#include <filesystem>
#include <map>

#include "saccade/core/error.h"

namespace saccade::components {

std::shared_ptr<const scene::Scene> LoadSharedScene(const std::string& path) {
  static std::map<std::string, std::weak_ptr<const scene::Scene>> cache;
  std::error_code error;
  std::string key = std::filesystem::weakly_canonical(path, error).string();
  if (error) key = path;
  if (std::shared_ptr<const scene::Scene> scene = cache[key].lock()) return scene;
  auto scene = std::make_shared<const scene::Scene>(scene::Scene::Load(path));
  cache[key] = scene;
  return scene;
}

const scene::Robot& RobotOf(const scene::Scene& scene, const std::string& path) {
  if (!scene.robot()) throw InvalidArgument("scene '" + path + "' has no robot: head");
  return *scene.robot();
}

}  // namespace saccade::components
