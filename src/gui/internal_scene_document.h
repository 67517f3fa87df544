#pragma once
// The scene document of the GUI protocol (docs/gui-protocol.md, GET /api/scene): lights, ground,
// models (each once, its meshes at /api/models/N.bin and textures at /api/textures/N.png),
// objects, the robot's parts and joints, the cameras; and the poses of the state message. Every
// pose is in geometry/json.h's one form: its 4x4 matrix, row by row, [[r00, r01, r02, x], ...,
// [0, 0, 0, 1]] (frames.jsonl's form too).
#include <nlohmann/json.hpp>
#include <string>

#include "saccade/head/head_model.h"
#include "saccade/scene/scene.h"
#include "saccade/server/gui_server.h"

namespace saccade::gui::internal {

/// The state's "frames" at `joints`: X_WB (the root), X_WC (midway between the optical
/// centres), links (every link by name), left and right (the optical frames).
nlohmann::json FramesJson(const head::HeadModel& head, const head::JointState& joints);

/// The state's "objects": the name and X_WO at time `t` (s) of each moving object.
nlohmann::json MovingObjectsJson(const scene::Scene& scene, double t);

/// Puts the models' and textures' documents on `server` and returns the scene document, with
/// `commands` (which commands this session offers) as its "commands".
nlohmann::json PublishScene(const scene::Scene& scene, const std::string& scene_name,
                            const std::string& mode, const nlohmann::json& commands,
                            server::GuiServer& server);

}  // namespace saccade::gui::internal
