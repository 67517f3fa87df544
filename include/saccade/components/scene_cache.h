#pragma once
// One loaded scene shared by every component of a process that names the same file, so that
// the cameras, the head and the controllers agree on one world and it is loaded once.
#include <memory>
#include <string>

#include "saccade/scene/scene.h"

namespace saccade::components {

/// The scene at `path`, loaded once while anything holds it (by canonical path). Throws
/// FileError as scene::Scene::Load. Not thread-safe (components configure on one thread).
std::shared_ptr<const scene::Scene> LoadSharedScene(const std::string& path);

/// The scene's robot; throws InvalidArgument naming the file when it has none.
const scene::Robot& RobotOf(const scene::Scene& scene, const std::string& path);

}  // namespace saccade::components
