#include <algorithm>
#include <cmath>

#include "gui/internal_scene_document.h"
#include "gui/internal_state_message.h"
#include "saccade/core/units.h"
#include "saccade/geometry/json.h"
#include "saccade/gui/protocol.h"
#include "saccade/head/fixation.h"
#include "saccade/head/json.h"

namespace saccade::gui::internal {
namespace {

using nlohmann::json;

double AxisErrorDeg(const geometry::Pose& X_WC, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d to = (p_W - X_WC.translation()).normalized();
  return std::acos(std::clamp(X_WC.linear().col(2).dot(to), -1.0, 1.0)) * kRadToDeg;
}

}  // namespace

json EffectsJson(const render::RendererOptions& o) {
  return {{"distortion", o.distortion},
          {"noise", o.noise},
          {"motion_blur", o.motion_blur},
          {"optics", o.optics},
          {"color", o.color}};
}

json StateJson(const StateParts& parts, const scene::Scene& scene) {
  json state = {{"type", "state"},
                {"step", parts.step},
                {"time", parts.time},
                {"paused", parts.paused},
                {"speed", parts.speed},
                {"perception", parts.perception},
                {"manual", !parts.perception}};
  state["effects"] = nullptr;
  if (parts.effects) {
    state["effects"] = EffectsJson(*parts.effects);
  }
  std::optional<std::array<geometry::Pose, 2>> cameras;
  state["joints"] = nullptr;
  state["frames"] = nullptr;
  state["fixation_W"] = nullptr;
  if (parts.joints && parts.head != nullptr) {
    const components::JointStateMessage& j = *parts.joints;
    state["joints"] = {{"positions", ToJson(j.positions)},
                       {"targets", ToJson(j.targets)},
                       {"velocities", ToJson(j.velocities)},
                       {"arrived", j.arrived}};
    state["frames"] = FramesJson(*parts.head, j.positions);
    cameras = parts.head->CameraPoses(j.positions);
    if (const auto p = head::FixationPoint((*cameras)[0], (*cameras)[1])) {
      state["fixation_W"] = ToJson(*p);
    }
  }
  state["target"] = nullptr;
  state["fixation_error_deg"] = nullptr;
  if (parts.target) {
    const components::TargetMessage& target = *parts.target;
    state["target"] = {{"valid", true}, {"p_W", ToJson(target.p_W)}, {"id", target.target_id}};
    if (cameras) {
      state["fixation_error_deg"] = {{"left", AxisErrorDeg((*cameras)[0], target.p_W)},
                                     {"right", AxisErrorDeg((*cameras)[1], target.p_W)}};
    }
  }
  state["objects"] = MovingObjectsJson(scene, parts.time);
  state["timing"] = {{"step_ms", parts.step_ms},
                     {"steps_per_s", parts.steps_per_s},
                     {"realtime_factor", parts.realtime_factor},
                     {"frames_per_s", parts.frames_per_s}};
  state["head_status"] = parts.head_status;
  state["recording"] = parts.recording;
  return state;
}

}  // namespace saccade::gui::internal

namespace saccade::gui::internal {

json MapJson(const components::MapMessage& m) {
  const std::size_t total = m.occupied_W.size();
  const std::size_t max = protocol::kMaxMapPoints;
  const std::size_t every = total <= max ? 1 : (total + max - 1) / max;
  const auto Mm = [](double v) { return std::round(v * 1000.0) / 1000.0; };
  std::vector<double> xyz;
  xyz.reserve(3 * std::min(total, max));
  for (std::size_t i = 0; i < total; i += every) {
    const Eigen::Vector3d& p = m.occupied_W[i];
    if (!p.allFinite()) continue;
    xyz.insert(xyz.end(), {Mm(p.x()), Mm(p.y()), Mm(p.z())});
  }
  json inhibited = json::array();
  for (const components::InhibitedPlace& place : m.inhibited) {
    if (!place.p_W.allFinite() || !std::isfinite(place.radius_m) ||
        !std::isfinite(place.strength)) {
      continue;
    }
    inhibited.push_back({{"p_W", {Mm(place.p_W.x()), Mm(place.p_W.y()), Mm(place.p_W.z())}},
                         {"radius_m", std::max(0.0, place.radius_m)},
                         {"strength", std::clamp(place.strength, 0.0, 1.0)}});
  }
  return {{"type", "map"},
          {"time", std::isfinite(m.time) ? m.time : 0.0},
          {"frame", m.frame_index},
          {"resolution_m", std::isfinite(m.resolution_m) ? std::max(0.0, m.resolution_m) : 0.0},
          {"fused", std::max<int64_t>(0, m.fused)},
          {"total", total},
          {"points", std::move(xyz)},
          {"inhibited", std::move(inhibited)}};
}

}  // namespace saccade::gui::internal
