#pragma once
// The state and map messages of the GUI protocol (docs/gui-protocol.md, `state`, `map`), built
// from what the session gathered after a step: apart from the session so that tests build them
// and check them against the protocol's table (tests/gui/protocol_test.cc).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>

#include "saccade/components/messages.h"
#include "saccade/head/head_model.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::gui::internal {

/// What a state says.
struct StateParts {
  int64_t step = 0;
  double time = 0.0;  ///< s, after the step
  bool paused = false;
  double speed = 1.0;  ///< simulated s per wall s, at most
  bool perception = false;
  /// The rendered cameras' effects; none when the cameras are real.
  std::optional<render::RendererOptions> effects;
  /// The head's joints, and its description for the frames; none without a head.
  std::optional<components::JointStateMessage> joints;
  const head::HeadModel* head = nullptr;
  /// Perception's target (a valid one), only while perception commands the head.
  std::optional<components::TargetMessage> target;
  double step_ms = 0.0;          ///< wall time of the last step
  double steps_per_s = 0.0;      ///< recently
  double realtime_factor = 0.0;  ///< simulated s per wall s, recently
  double frames_per_s = 0.0;     ///< images encoded per second, recently
  nlohmann::json head_status;    ///< hw.head's newest status, null without one
  nlohmann::json recording;      ///< {file, megabytes} of the recording, null without one
};

/// The effects' switches as the protocol writes them (`effects`: distortion, noise, motion_blur,
/// optics, color).
nlohmann::json EffectsJson(const render::RendererOptions& options);

/// The state message: the joints with the head's frames (forward kinematics), the target with
/// each optical axis's error to it, and the poses of `scene`'s moving objects at `parts.time`.
nlohmann::json StateJson(const StateParts& parts, const scene::Scene& scene);

/// The map message of `m`: every voxel, or every k-th beyond protocol::kMaxMapPoints (k =
/// ceil(total / kMaxMapPoints)), to the millimetre; points and places that are not finite left
/// out, strengths clamped to [0, 1].
nlohmann::json MapJson(const components::MapMessage& m);

}  // namespace saccade::gui::internal
