#pragma once
// The scene document of the GUI protocol (docs/gui-protocol.md, GET /api/scene): lights, ground,
// models (each once, its meshes at /api/models/N.bin and textures at /api/textures/N.png),
// objects, the robot's parts and joints, the cameras.
#include <nlohmann/json.hpp>
#include <string>

#include "saccade/scene/scene.h"
#include "saccade/server/gui_server.h"

namespace saccade::gui::internal {

/// A pose as 16 numbers, row-major: the protocol's form (three.js's Matrix4.set order).
nlohmann::json MatrixJson(const geometry::Pose& X);

/// Puts the models' and textures' documents on `server` and returns the scene document, with
/// `commands` (which commands this session offers) as its "commands".
nlohmann::json PublishScene(const scene::Scene& scene, const std::string& scene_name,
                            const std::string& mode, const nlohmann::json& commands,
                            server::GuiServer& server);

}  // namespace saccade::gui::internal
