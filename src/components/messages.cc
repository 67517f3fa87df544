#include "saccade/components/messages.h"

#include <fmt/format.h>

#include <string>

namespace saccade::components {

bool JointCommand::pursuit() const {
  return velocities.pan != 0.0 || velocities.tilt != 0.0 || velocities.left != 0.0 ||
         velocities.right != 0.0;
}

void RegisterMessages() {
  runtime::MessageRegistry& registry = runtime::MessageRegistry::Global();
  registry.Register<JointStateMessage>();
  registry.Register<JointCommand>();
  registry.Register<HeadStatusMessage>();
  registry.Register<FacesMessage>();
  registry.Register<CandidatesMessage>();
  registry.Register<SelectionMessage>();
  registry.Register<TrackMessage>();
  registry.Register<TargetMessage>();
}

}  // namespace saccade::components

namespace saccade::runtime {
namespace {

using components::CandidatesMessage;
using components::FaceCandidate;
using components::FacesMessage;
using components::HeadStatusMessage;
using components::JointCommand;
using components::JointStateMessage;
using components::SelectionMessage;
using components::TargetMessage;
using components::TrackMessage;
using nlohmann::json;

json JointsToJson(const head::JointState& q) {
  return {{"pan", q.pan}, {"tilt", q.tilt}, {"left", q.left}, {"right", q.right}};
}

head::JointState JointsFromJson(const json& j, const char* type, const char* key) {
  const json& value = JsonField(j, type, key);
  const std::string where = std::string(type) + "." + key;  // "head.joints.positions"
  head::JointState q;
  q.pan = JsonNumber(value, where.c_str(), "pan");
  q.tilt = JsonNumber(value, where.c_str(), "tilt");
  q.left = JsonNumber(value, where.c_str(), "left");
  q.right = JsonNumber(value, where.c_str(), "right");
  return q;
}

json VectorToJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Vector3d VectorFromJson(const json& j, const char* type, const char* key) {
  const std::vector<double> v = JsonNumbers(j, type, key, 3);
  return {v[0], v[1], v[2]};
}

json RectToJson(const cv::Rect& r) { return {r.x, r.y, r.width, r.height}; }

cv::Rect RectFromJson(const json& j, const char* type, const char* key) {
  const std::vector<double> v = JsonNumbers(j, type, key, 4);
  for (double x : v) {
    if (x != static_cast<int>(x) || v[2] < 0 || v[3] < 0) {
      throw Error(
          fmt::format("{}: field '{}': expected [x, y, width, height] in whole pixels, "
                      "width and height >= 0, got {}",
                      type, key, JsonField(j, type, key).dump()));
    }
  }
  return {static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]),
          static_cast<int>(v[3])};
}

// Images: metadata only (messages.h).
json ImageToJson(const std::shared_ptr<const Image>& image) {
  if (!image) return nullptr;
  const ImageMetadata& meta = image->metadata();
  return {{"camera", meta.camera}, {"frame_index", meta.frame_index}, {"time", meta.time}};
}

}  // namespace

json MessageTraits<JointStateMessage>::ToJson(const JointStateMessage& m) {
  return {{"time", m.time},
          {"positions", JointsToJson(m.positions)},
          {"velocities", JointsToJson(m.velocities)},
          {"targets", JointsToJson(m.targets)},
          {"arrived", m.arrived},
          {"clamped_commands", m.clamped_commands}};
}

JointStateMessage MessageTraits<JointStateMessage>::FromJson(const json& j) {
  JointStateMessage m;
  m.time = JsonNumber(j, kName, "time");
  m.positions = JointsFromJson(j, kName, "positions");
  m.velocities = JointsFromJson(j, kName, "velocities");
  m.targets = JointsFromJson(j, kName, "targets");
  m.arrived = JsonBool(j, kName, "arrived");
  m.clamped_commands = JsonInteger(j, kName, "clamped_commands");
  return m;
}

json MessageTraits<JointCommand>::ToJson(const JointCommand& m) {
  return {{"time", m.time},
          {"positions", JointsToJson(m.positions)},
          {"velocities", JointsToJson(m.velocities)},
          {"target_id", m.target_id}};
}

JointCommand MessageTraits<JointCommand>::FromJson(const json& j) {
  JointCommand m;
  m.time = JsonNumber(j, kName, "time");
  m.positions = JointsFromJson(j, kName, "positions");
  m.velocities = JointsFromJson(j, kName, "velocities");
  m.target_id = JsonInteger(j, kName, "target_id");
  return m;
}

json MessageTraits<HeadStatusMessage>::ToJson(const HeadStatusMessage& m) {
  return {{"time", m.time},
          {"driver", m.driver},
          {"positions", JointsToJson(m.positions)},
          {"velocities", JointsToJson(m.velocities)},
          {"targets", JointsToJson(m.targets)},
          {"torque", m.torque},
          {"holding", m.holding},
          {"emergency_stopped", m.emergency_stopped},
          {"fault", m.fault},
          {"commands", m.commands},
          {"rejected_commands", m.rejected_commands},
          {"limited_commands", m.limited_commands},
          {"watchdog_trips", m.watchdog_trips},
          {"last_limit", m.last_limit},
          {"mirror", m.mirror}};
}

HeadStatusMessage MessageTraits<HeadStatusMessage>::FromJson(const json& j) {
  HeadStatusMessage m;
  m.time = JsonNumber(j, kName, "time");
  m.driver = JsonString(j, kName, "driver");
  m.positions = JointsFromJson(j, kName, "positions");
  m.velocities = JointsFromJson(j, kName, "velocities");
  m.targets = JointsFromJson(j, kName, "targets");
  m.torque = JsonBool(j, kName, "torque");
  m.holding = JsonBool(j, kName, "holding");
  m.emergency_stopped = JsonBool(j, kName, "emergency_stopped");
  m.fault = JsonString(j, kName, "fault");
  m.commands = JsonInteger(j, kName, "commands");
  m.rejected_commands = JsonInteger(j, kName, "rejected_commands");
  m.limited_commands = JsonInteger(j, kName, "limited_commands");
  m.watchdog_trips = JsonInteger(j, kName, "watchdog_trips");
  m.last_limit = JsonString(j, kName, "last_limit");
  m.mirror = JsonBool(j, kName, "mirror");
  return m;
}

json MessageTraits<FacesMessage>::ToJson(const FacesMessage& m) {
  json faces = json::array();
  for (const FacesMessage::Face& f : m.faces) {
    faces.push_back({{"box", RectToJson(f.box)},
                     {"neighbors", f.neighbors},
                     {"rejected", f.rejected},
                     {"reason", f.reason}});
  }
  return {{"image", ImageToJson(m.image)}, {"faces", faces}};
}

FacesMessage MessageTraits<FacesMessage>::FromJson(const json& j) {
  FacesMessage m;
  const json& faces = JsonField(j, kName, "faces");
  if (!faces.is_array()) {
    throw Error(fmt::format("{}: field 'faces': expected an array, got {}", kName, faces.dump()));
  }
  for (const json& f : faces) {
    FacesMessage::Face face;
    face.box = RectFromJson(f, kName, "box");
    face.neighbors = static_cast<int>(JsonInteger(f, kName, "neighbors"));
    face.rejected = JsonBool(f, kName, "rejected");
    face.reason = JsonString(f, kName, "reason");
    m.faces.push_back(std::move(face));
  }
  return m;
}

json MessageTraits<CandidatesMessage>::ToJson(const CandidatesMessage& m) {
  json candidates = json::array();
  for (const FaceCandidate& c : m.candidates) {
    candidates.push_back({{"p_W", VectorToJson(c.p_W)},
                          {"left_box", RectToJson(c.left_box)},
                          {"right_box", RectToJson(c.right_box)},
                          {"distance_m", c.distance_m},
                          {"reprojection_px", c.reprojection_px},
                          {"gap_m", c.gap_m},
                          {"width_m", c.width_m}});
  }
  return {{"time", m.time}, {"frame_index", m.frame_index}, {"candidates", candidates}};
}

CandidatesMessage MessageTraits<CandidatesMessage>::FromJson(const json& j) {
  CandidatesMessage m;
  m.time = JsonNumber(j, kName, "time");
  m.frame_index = JsonInteger(j, kName, "frame_index");
  const json& candidates = JsonField(j, kName, "candidates");
  if (!candidates.is_array()) {
    throw Error(
        fmt::format("{}: field 'candidates': expected an array, got {}", kName, candidates.dump()));
  }
  for (const json& c : candidates) {
    FaceCandidate candidate;
    candidate.p_W = VectorFromJson(c, kName, "p_W");
    candidate.left_box = RectFromJson(c, kName, "left_box");
    candidate.right_box = RectFromJson(c, kName, "right_box");
    candidate.distance_m = JsonNumber(c, kName, "distance_m");
    candidate.reprojection_px = JsonNumber(c, kName, "reprojection_px");
    candidate.gap_m = JsonNumber(c, kName, "gap_m");
    candidate.width_m = JsonNumber(c, kName, "width_m");
    m.candidates.push_back(candidate);
  }
  return m;
}

json MessageTraits<SelectionMessage>::ToJson(const SelectionMessage& m) {
  json suppressed = json::array();
  for (const Eigen::Vector3d& p : m.suppressed_W) suppressed.push_back(VectorToJson(p));
  return {{"time", m.time},
          {"frame_index", m.frame_index},
          {"valid", m.valid},
          {"target_id", m.target_id},
          {"p_W", VectorToJson(m.p_W)},
          {"boxes_fresh", m.boxes_fresh},
          {"left_box", RectToJson(m.left_box)},
          {"right_box", RectToJson(m.right_box)},
          {"fixating", m.fixating},
          {"exploring", m.exploring},
          {"dwell_s", m.dwell_s},
          {"suppressed_W", suppressed}};
}

SelectionMessage MessageTraits<SelectionMessage>::FromJson(const json& j) {
  SelectionMessage m;
  m.time = JsonNumber(j, kName, "time");
  m.frame_index = JsonInteger(j, kName, "frame_index");
  m.valid = JsonBool(j, kName, "valid");
  m.target_id = JsonInteger(j, kName, "target_id");
  m.p_W = VectorFromJson(j, kName, "p_W");
  m.boxes_fresh = JsonBool(j, kName, "boxes_fresh");
  m.left_box = RectFromJson(j, kName, "left_box");
  m.right_box = RectFromJson(j, kName, "right_box");
  m.fixating = JsonBool(j, kName, "fixating");
  m.exploring = JsonBool(j, kName, "exploring");
  m.dwell_s = JsonNumber(j, kName, "dwell_s");
  const json& suppressed = JsonField(j, kName, "suppressed_W");
  if (!suppressed.is_array()) {
    throw Error(fmt::format("{}: field 'suppressed_W': expected an array, got {}", kName,
                            suppressed.dump()));
  }
  for (const json& p : suppressed) {
    m.suppressed_W.push_back(VectorFromJson(json{{"p", p}}, kName, "p"));
  }
  return m;
}

json MessageTraits<TrackMessage>::ToJson(const TrackMessage& m) {
  return {{"image", ImageToJson(m.image)},
          {"target_id", m.target_id},
          {"tracking", m.tracking},
          {"window", RectToJson(m.window)},
          {"center", {m.center.x, m.center.y}},
          {"reseeded", m.reseeded},
          {"reason", m.reason}};
}

TrackMessage MessageTraits<TrackMessage>::FromJson(const json& j) {
  TrackMessage m;
  m.target_id = JsonInteger(j, kName, "target_id");
  m.tracking = JsonBool(j, kName, "tracking");
  m.window = RectFromJson(j, kName, "window");
  const std::vector<double> c = JsonNumbers(j, kName, "center", 2);
  m.center = {c[0], c[1]};
  m.reseeded = JsonBool(j, kName, "reseeded");
  m.reason = JsonString(j, kName, "reason");
  return m;
}

json MessageTraits<TargetMessage>::ToJson(const TargetMessage& m) {
  return {{"time", m.time},
          {"frame_index", m.frame_index},
          {"valid", m.valid},
          {"target_id", m.target_id},
          {"p_W", VectorToJson(m.p_W)},
          {"source", m.source},
          {"reprojection_px", m.reprojection_px},
          {"gap_m", m.gap_m}};
}

TargetMessage MessageTraits<TargetMessage>::FromJson(const json& j) {
  TargetMessage m;
  m.time = JsonNumber(j, kName, "time");
  m.frame_index = JsonInteger(j, kName, "frame_index");
  m.valid = JsonBool(j, kName, "valid");
  m.target_id = JsonInteger(j, kName, "target_id");
  m.p_W = VectorFromJson(j, kName, "p_W");
  m.source = JsonString(j, kName, "source");
  m.reprojection_px = JsonNumber(j, kName, "reprojection_px");
  m.gap_m = JsonNumber(j, kName, "gap_m");
  return m;
}

}  // namespace saccade::runtime
