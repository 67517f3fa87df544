#include "saccade/gui/session.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "gui/internal_scene_document.h"
#include "gui/internal_state_message.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/core/units.h"
#include "saccade/geometry/json.h"
#include "saccade/gui/protocol.h"
#include "saccade/head/fixation.h"
#include "saccade/head/json.h"
#include "saccade/head/kinematics.h"
#include "saccade/vision/image_camera.h"

namespace saccade::gui {
namespace {

namespace fs = std::filesystem;
using components::HeadStatusMessage;
using components::JointCommand;
using nlohmann::json;
using server::CommandError;

double WallNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// A message of the server's own that breaks the protocol's table is a bug here (or in the
/// table): said in the log, the first few times, and sent anyway.
void Conform(const std::string& problem) {
  static std::atomic<int> said{0};
  if (problem.empty() || said.fetch_add(1) >= 5) return;
  log::Error("gui: a message of the server breaks docs/gui-protocol.md (a bug): {}", problem);
}

/// An event for every client (docs/gui-protocol.md, `event`).
json Event(const std::string& level, const std::string& message) {
  json event = {{"type", "event"}, {"level", level}, {"message", message}};
  Conform(protocol::CheckServerMessage(event));
  return event;
}

}  // namespace

GuiSession::GuiSession(runtime::Pipeline& pipeline, const scene::Scene& scene,
                       const std::string& scene_name, const GuiOptions& options)
    : scene_(scene), options_(options), control_(options.paused) {
  CheckCommandTable();
  perception_ = options.perception;
  if (!(options.speed >= 0.05 && options.speed <= 10.0)) {
    throw InvalidArgument(fmt::format("--speed must be in [0.05, 10], got {}", options.speed));
  }
  control_.SetSpeed(options.speed);
  recording_ = options.recording;
  if (recording_) recording_json_ = {{"file", recording_->file()}, {"megabytes", 0.0}};
  if (options.port < 0 || options.port > 65535) {
    throw InvalidArgument(fmt::format("--port must be in [0, 65535], got {}", options.port));
  }
  // The robot, by its roles; perception is every component that does not stand for it.
  head_ = pipeline.FindRole<components::HeadRole>();
  hw_head_ = head_ != nullptr && head_->has_emergency_stop();
  cameras_ = pipeline.FindRole<components::EyeCamerasRole>();
  rendered_ = cameras_ != nullptr && cameras_->rendered() != nullptr;
  // The readers of the robot's topics (a robot in another process, pipelines/remote.yaml)
  // belong to the robot too.
  std::set<std::string> robot;
  for (const auto& component : pipeline.components()) {
    if (components::IsRobotRole(*component)) robot.insert(component->name());
  }
  for (std::size_t k = 0; k < pipeline.components().size(); ++k) {
    const auto& component = pipeline.components()[k];
    const auto& specs = pipeline.spec().components;  // in the components' order
    const std::string reads_for = k < specs.size() ? specs[k].reads_for : std::string();
    if (robot.contains(component->name()) || robot.contains(reads_for)) continue;
    perception_components_.push_back(component.get());
    component->SetEnabled(options.perception);
  }
  if (rendered_) effects_ = *cameras_->rendered();
  // The GUI shows the loop as it goes: the next frame renders while this one is processed.
  if (cameras_ != nullptr) cameras_->SetPipelined(true);
  Tap<HeadStatusMessage>(pipeline, [this](const HeadStatusMessage& m) {
    head_status_ = runtime::MessageTraits<HeadStatusMessage>::ToJson(m);
  });
  TapMap(pipeline);
  if (scene_.robot()) targets_ = scene_.robot()->initial_joints;

  server::ServerOptions server_options;
  server_options.address = options.listen;
  server_options.port = static_cast<uint16_t>(options.port);
  server_options.token = options.token;
  // --token, else $SACCADE_GUI_TOKEN (but not with --no-token).
  if (server_options.token.empty() && !options.no_token) {
    if (const char* token = std::getenv("SACCADE_GUI_TOKEN")) server_options.token = token;
  }
  server_options.allowed_hosts = options.allowed_hosts;
  if (options.no_token) {
    if (!options.token.empty()) throw InvalidArgument("gui: --no-token and --token contradict");
    if (!server::IsLoopbackAddress(options.listen)) {
      throw InvalidArgument("gui: --no-token is for loopback addresses only; --listen " +
                            options.listen +
                            " needs a token (--token TOKEN, or none for a "
                            "random one)");
    }
  } else if (server_options.token.empty() && server::IsLoopbackAddress(options.listen)) {
    // As Jupyter does: a random token in the printed address, so that another local user or a
    // page that guesses the port cannot drive the head. (Off loopback the server refuses to
    // start without a token given by the operator.)
    server_options.token = server::GenerateToken();
  }
  const fs::path web = options.web_dir;
  if (!fs::exists(web / "public" / "index.html")) {
    throw Error("gui: the page is missing: " + (web / "public" / "index.html").string());
  }
  if (!fs::exists(web / "node_modules" / "three" / "build" / "three.module.js")) {
    throw Error("gui: three.js is missing from " + (web / "node_modules").string() +
                ": run `bash scripts/setup.sh` (it installs web/package-lock.json with npm)");
  }
  server_options.mounts = {{"/", (web / "public").string()},
                           {"/vendor/three/", (web / "node_modules" / "three").string()}};
  server_options.hello = {{"mode", options.mode}};
  server_ = std::make_unique<server::GuiServer>(server_options);

  const json commands = {
      {"effects", rendered_}, {"perception", !perception_components_.empty()}, {"estop", hw_head_}};
  const json scene_json =
      internal::PublishScene(scene_, scene_name, options.mode, commands, *server_);
  Conform(protocol::CheckSceneDocument(scene_json));
  server_->SetDocument("/api/scene", "application/json", scene_json.dump());
  server_->SetCommandHandler(
      [this](const json& command, int64_t client) { return Handle(command, client); });
  server_->Start();
  encoder_ = std::thread([this] { EncodeLoop(); });
}

GuiSession::~GuiSession() {
  {
    std::lock_guard lock(encode_mutex_);
    encoder_stop_ = true;
  }
  encode_cv_.notify_all();
  if (encoder_.joinable()) encoder_.join();
  server_->Stop();
  if (recording_) {
    try {
      fmt::print("{}", recording_->Close());
    } catch (const std::exception& e) {
      log::Log(log::Level::kWarn, "gui: the recording did not close: {}", e.what());
    }
  }
}

std::string GuiSession::Describe() const {
  const std::vector<server::ClientStats> clients = server_->clients();
  int64_t sent = 0, skipped = 0;
  for (const server::ClientStats& c : clients) {
    sent += c.frames_sent;
    skipped += c.frames_skipped;
  }
  return fmt::format(
      "gui: {} client(s) now; {} images encoded; to the clients now: {} frames sent, "
      "{} skipped for slow clients",
      clients.size(), frames_encoded_.load(), sent, skipped);
}

head::JointState GuiSession::CurrentTargets() const {
  std::lock_guard lock(joints_mutex_);
  return targets_;
}

void GuiSession::Enqueue(std::function<void()> action) {
  std::lock_guard lock(queue_mutex_);
  queue_.push_back(std::move(action));
}

int GuiSession::ApplyQueued() {
  std::vector<std::function<void()>> actions;
  {
    std::lock_guard lock(queue_mutex_);
    actions.swap(queue_);
  }
  for (auto& action : actions) {
    try {
      action();
    } catch (const std::exception& error) {
      server_->Broadcast(Event("error", error.what()));
    }
  }
  return static_cast<int>(actions.size());
}

void GuiSession::SetPerception(bool enabled) {
  for (runtime::Component* c : perception_components_) c->SetEnabled(enabled);
  perception_ = enabled;
}

// The commands of the protocol's table that the session answers (the server module answers
// frame_window and frame_ack itself): the constructor holds the two lists equal.
const std::map<std::string, GuiSession::CommandFn>& GuiSession::CommandTable() {
  static const std::map<std::string, CommandFn> table = {{"joints", &GuiSession::OnJoints},
                                                         {"fixate", &GuiSession::OnFixate},
                                                         {"perception", &GuiSession::OnPerception},
                                                         {"effects", &GuiSession::OnEffects},
                                                         {"pause", &GuiSession::OnPause},
                                                         {"resume", &GuiSession::OnResume},
                                                         {"step", &GuiSession::OnStep},
                                                         {"speed", &GuiSession::OnSpeed},
                                                         {"record", &GuiSession::OnRecord},
                                                         {"stop", &GuiSession::OnHeadStop},
                                                         {"estop", &GuiSession::OnHeadStop},
                                                         {"clear", &GuiSession::OnHeadStop},
                                                         {"ping", &GuiSession::OnPing}};
  return table;
}

void GuiSession::CheckCommandTable() {
  std::vector<std::string> declared, handled;
  for (const protocol::Message& m : protocol::Messages()) {
    if (m.channel == protocol::Channel::kCommand && !m.transport) declared.push_back(m.type);
  }
  for (const auto& [type, unused] : CommandTable()) handled.push_back(type);
  std::sort(declared.begin(), declared.end());
  if (declared != handled) {
    throw Error("gui: the protocol's commands and the session's handlers differ (a bug)");
  }
}

json GuiSession::Handle(const json& command, int64_t client) {
  (void)client;
  // The protocol's table first: a command that breaks it is refused naming the field.
  if (const std::string problem = protocol::CheckCommand(command); !problem.empty()) {
    throw CommandError(problem);
  }
  const std::string type = command["type"].get<std::string>();
  const auto handler = CommandTable().find(type);
  if (handler == CommandTable().end()) {
    throw CommandError(type + ": the server module answers it, not the session");
  }
  const json reply = (this->*handler->second)(command);
  json message = reply;  // as the server module sends it
  message["type"] = "reply";
  message["id"] = command["id"];
  message["ok"] = true;
  Conform(protocol::CheckServerMessage(message, type));
  return reply;
}

const head::HeadModel& GuiSession::RequireHead(const std::string& type) const {
  if (!head_ || !scene_.robot()) throw CommandError(type + ": this pipeline has no head to move");
  return scene_.robot()->head;
}

json GuiSession::MoveTo(const head::JointState& target, json reply) {
  {
    std::lock_guard lock(joints_mutex_);
    targets_ = target;
  }
  Enqueue([this, target] {
    SetPerception(false);  // the hand overrides the loop
    JointCommand c;
    c.time = sim_time_;
    c.positions = target;
    c.velocities = head::JointState(target.shared_names());
    commanded_ = head_->Move(c);
  });
  reply["targets"] = ToJson(target);
  reply["perception"] = false;
  return reply;
}

json GuiSession::OnJoints(const json& command) {
  const head::HeadModel& head = RequireHead("joints");
  head::JointState target = head.Arrange(CurrentTargets());
  // Joint names of the head (the table checks the values are numbers, at least one), and
  // "vergence" for the head's first symmetric pair unless a joint has that name.
  for (const auto& [name, value] : command["positions"].items()) {
    if (!value.is_number()) {
      throw CommandError(fmt::format("joints: positions.{} must be a number", name));
    }
    const double x = value.get<double>();
    const int j = head.FindJoint(name);
    if (j < 0 && name == "vergence" && !head.fixation_rule().symmetric.empty()) {
      // Symmetric vergence (seed appendix A): > 0 converges, POPEYE's left eye turning right.
      const head::FixationRule::Pair& pair = head.fixation_rule().symmetric.front();
      target[pair.a] = -x;
      target[pair.b] = pair.sign * -x;
      continue;
    }
    if (j < 0) {
      throw CommandError(fmt::format("joints: the head has no joint '{}'; its joints are: {}", name,
                                     head::ListNames(*head.joint_names())));
    }
    if (!head.joint(j).driven) {
      throw CommandError(fmt::format("joints: the head holds joint '{}' (not driven)", name));
    }
    target[j] = x;
  }
  // The server's check (docs/gui-protocol.md): a value outside the limits refuses the whole
  // command; the page's clamping is a convenience, never the safety.
  for (int j = 0; j < head.num_joints(); ++j) {
    const head::JointLimits& l = head.joint(j).limits;
    if (!l.Contains(target[j])) {
      throw CommandError(fmt::format(
          "joints: {} {:.4f} rad ({:.2f} deg) is outside its limits [{:.4f}, {:.4f}] rad",
          head.joint_name(j), target[j], target[j] * kRadToDeg, l.min, l.max));
    }
  }
  return MoveTo(target, json::object());
}

json GuiSession::OnFixate(const json& command) {
  const head::HeadModel& head = RequireHead("fixate");
  const json& p = command["p_W"];  // three numbers (the table's point)
  const Eigen::Vector3d p_W(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  const head::JointState seed = head.Arrange(CurrentTargets());
  // POPEYE's legacy head: appendix A's solver, as the loop's fixation; any other: fixation.h.
  if (const std::optional<head::HeadDescription> legacy = head.AppendixAHead()) {
    head::IkOptions ik;
    ik.seed = {seed[0], seed[1], seed[2], seed[3]};
    const head::IkResult solution = head::SolveFixation(*legacy, p_W, ik);
    if (!solution.reachable()) {
      throw CommandError(fmt::format("fixate: [{:.3f}, {:.3f}, {:.3f}] cannot be fixated: {}",
                                     p_W.x(), p_W.y(), p_W.z(), solution.message));
    }
    const head::PopeyeJoints& q = solution.joints;
    return MoveTo(head.State(Eigen::Vector4d(q.pan, q.tilt, q.left, q.right)),
                  {{"axis_error_deg", solution.axis_error * kRadToDeg}});
  }
  head::FixationOptions options;
  options.seed = seed.values();
  const head::FixationResult solution = head::SolveFixation(head, p_W, options);
  if (!solution.reachable()) {
    throw CommandError(fmt::format("fixate: [{:.3f}, {:.3f}, {:.3f}] cannot be fixated: {}",
                                   p_W.x(), p_W.y(), p_W.z(), solution.message));
  }
  return MoveTo(head.State(solution.joints), {{"axis_error_deg", solution.axis_error * kRadToDeg}});
}

json GuiSession::OnPerception(const json& command) {
  if (perception_components_.empty()) {
    throw CommandError("perception: this pipeline has no components besides the robot");
  }
  const bool enabled = command.value("enabled", perception_.load());
  Enqueue([this, enabled] { SetPerception(enabled); });
  return {{"perception", enabled}};
}

json GuiSession::OnEffects(const json& command) {
  if (!rendered_) {
    throw CommandError("effects: the cameras are not simulated: they have no effects to switch");
  }
  std::lock_guard lock(effects_mutex_);
  render::EffectSwitches effects = render::EffectSwitches::Of(effects_);
  effects.distortion = command.value("distortion", effects.distortion);
  effects.noise = command.value("noise", effects.noise);
  effects.motion_blur = command.value("motion_blur", effects.motion_blur);
  effects.optics = command.value("optics", effects.optics);
  effects.color = command.value("color", effects.color);
  effects.ApplyTo(&effects_);
  Enqueue([this, effects] { cameras_->SetEffects(effects); });
  return {{"effects", internal::EffectsJson(effects_)}};
}

json GuiSession::OnPause(const json&) {
  control_.Pause();
  return {{"paused", true}};
}

json GuiSession::OnResume(const json&) {
  control_.Resume();
  return {{"paused", false}};
}

json GuiSession::OnStep(const json& command) {
  const int count = command.value("count", 1);  // the table holds it to [1, 1000]
  if (!control_.paused()) {
    throw CommandError("step: pause first (steps are for a paused simulation)");
  }
  control_.Step(count);
  return {{"steps", count}};
}

json GuiSession::OnSpeed(const json& command) {
  const double factor = command["factor"].get<double>();  // the table holds it to [0.05, 10]
  control_.SetSpeed(factor);
  return {{"speed", factor}};
}

json GuiSession::OnHeadStop(const json& command) {
  const std::string type = command["type"].get<std::string>();
  if (!head_) throw CommandError(type + ": this pipeline has no head");
  if (type != "stop" && !hw_head_) {
    throw CommandError(type +
                       ": only a hardware head (hw.head) has an emergency stop; use stop to "
                       "brake the simulated one");
  }
  Enqueue([this, type] {
    SetPerception(false);
    if (type == "stop") {
      head_->StopHead();
    } else if (type == "estop") {
      head_->EmergencyStop();
    } else {
      head_->ClearFault();
    }
  });
  return {{"perception", false}};
}

json GuiSession::OnRecord(const json& command) {
  const bool enabled = command["enabled"].get<bool>();
  if (enabled && !options_.start_recording) {
    throw CommandError("record: this server records nowhere (start it with --record-dir)");
  }
  Enqueue([this, enabled] {
    if (recording_ && !enabled) {
      const std::string line = recording_->Close();
      fmt::print("{}", line);
      recording_.reset();
    } else if (!recording_ && enabled) {
      try {
        recording_ = options_.start_recording();
        fmt::print("gui: recording to {}\n", recording_->file());
      } catch (const std::exception& e) {
        log::Log(log::Level::kWarn, "gui: cannot record: {}", e.what());
      }
    }
    std::fflush(stdout);
    std::lock_guard lock(recording_mutex_);
    recording_json_ = recording_ ? json{{"file", recording_->file()}, {"megabytes", 0.0}} : json();
  });
  return {{"recording", enabled}};
}

json GuiSession::OnPing(const json&) { return {{"time", sim_time_.load()}}; }

json GuiSession::StateJson(const runtime::StepContext& context, const Latest& latest) {
  internal::StateParts parts;
  parts.step = context.step;
  parts.time = context.time + context.dt;  // the state after this step
  parts.paused = control_.paused();
  parts.speed = control_.speed();
  parts.perception = perception_.load();
  if (rendered_) parts.effects = *cameras_->rendered();
  const std::optional<JointStateMessage>& joints = commanded_ ? commanded_ : latest.joints;
  if (joints && scene_.robot()) {
    parts.joints = *joints;
    parts.head = &scene_.robot()->head;
    std::lock_guard lock(joints_mutex_);
    if (perception_) targets_ = joints->targets;  // partial hand commands start from here
  }
  if (perception_ && latest.target && latest.target->valid) parts.target = *latest.target;
  const double now = WallNow();
  if (step_walls_.size() >= 2) {
    parts.steps_per_s =
        (step_walls_.size() - 1) / std::max(1e-9, step_walls_.back() - step_walls_.front());
  }
  {
    std::lock_guard lock(encode_mutex_);
    if (encode_walls_.size() >= 2 && now - encode_walls_.back() < 2.0) {
      parts.frames_per_s =
          (encode_walls_.size() - 1) / std::max(1e-9, encode_walls_.back() - encode_walls_.front());
    }
  }
  parts.step_ms = last_step_ms_;
  parts.realtime_factor = parts.steps_per_s * context.dt;
  parts.head_status = head_status_;
  {
    std::lock_guard lock(recording_mutex_);
    parts.recording = recording_json_;
  }
  json state = internal::StateJson(parts, scene_);
  Conform(protocol::CheckServerMessage(state));
  return state;
}

void GuiSession::AfterStep(const runtime::StepContext& context, const Latest& latest,
                           const std::atomic<bool>& stop) {
  const double arrived = WallNow();
  if (last_return_wall_ >= 0.0) last_step_ms_ = 1e3 * (arrived - last_return_wall_);
  step_walls_.push_back(arrived);
  if (step_walls_.size() > 26) step_walls_.erase(step_walls_.begin());
  sim_time_ = context.time + context.dt;

  commanded_.reset();  // this step's joints are the newest
  if (recording_) {
    recording_->AfterStep(context);
    std::lock_guard lock(recording_mutex_);
    recording_json_ = {{"file", recording_->file()},
                       {"megabytes", static_cast<double>(recording_->bytes()) / 1e6}};
  }
  last_context_ = context;
  last_context_->while_waiting = nullptr;
  last_latest_ = &latest;
  ApplyQueued();
  server_->PublishState(StateJson(context, latest));
  PublishMap(context.step, control_.paused());

  // The newest images to the encoder (it drops what it has not started on).
  const auto left = latest.images.find("left");
  const int64_t frame =
      left != latest.images.end() && left->second ? left->second->metadata().frame_index : -1;
  if (server_->client_count() > 0 && frame != last_frame_sent_) {
    last_frame_sent_ = frame;
    std::lock_guard lock(encode_mutex_);
    to_encode_ = latest;
    if (!perception_) {  // no stale detections over live images
      to_encode_->faces.clear();
      to_encode_->tracks.clear();
      to_encode_->target.reset();
      to_encode_->selection.reset();
    }
    encode_cv_.notify_one();
  }

  // Pause, single steps and the pace (runtime/run_control.h), applying commands meanwhile.
  int64_t waited = 0;
  control_.WaitBeforeNext(context, stop, [&](bool paused) {
    if (!paused) {
      // A hand command while the loop waits for its pace: the page sees its targets at once.
      if (ApplyQueued() > 0) server_->PublishState(StateJson(context, latest));
      return;
    }
    bool pending = false;
    {
      std::lock_guard lock(queue_mutex_);
      pending = !queue_.empty();
    }
    if (pending || ++waited % 10 == 0) {
      // Commands while paused take effect (targets) and the page sees them.
      ApplyQueued();
      server_->PublishState(StateJson(context, latest));
      PublishMap(context.step, true);
    }
  });
  last_return_wall_ = WallNow();
}

void GuiSession::TapMap(runtime::Pipeline& pipeline) {
  for (const auto& component : pipeline.components()) {
    for (const auto& output : component->outputs()) {
      auto* typed = dynamic_cast<runtime::Output<components::MapMessage>*>(output.get());
      if (typed == nullptr) continue;
      typed->signal().Connect([this](const components::MapMessage& m) {
        auto copy = std::make_shared<const components::MapMessage>(m);
        std::lock_guard lock(map_mutex_);
        map_ = std::move(copy);
        map_pending_ = true;
      });
      return;  // the first one
    }
  }
}

void GuiSession::PublishMap(int64_t step, bool now) {
  std::shared_ptr<const components::MapMessage> map;
  {
    std::lock_guard lock(map_mutex_);
    if (!map_pending_ || (!now && step - map_sent_step_ < protocol::kMapEverySteps)) return;
    map = map_;
    map_pending_ = false;
    map_sent_step_ = step;
  }
  const json message = internal::MapJson(*map);
  Conform(protocol::CheckServerMessage(message));
  server_->PublishLatest("map", message);
}

void GuiSession::WhileWaiting() {
  if (ApplyQueued() > 0 && last_context_ && last_latest_ != nullptr) {
    server_->PublishState(StateJson(*last_context_, *last_latest_));
  }
}

void GuiSession::EncodeLoop() {
  while (true) {
    Latest latest;
    {
      std::unique_lock lock(encode_mutex_);
      encode_cv_.wait(lock, [this] { return encoder_stop_ || to_encode_.has_value(); });
      if (encoder_stop_) return;
      latest = std::move(*to_encode_);
      to_encode_.reset();
    }
    try {
      for (const auto& [camera, image] : latest.images) {
        if (!image) continue;
        const cv::Mat bgr = Annotate(latest, camera, 1.0);
        std::vector<uint8_t> jpeg;
        cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality});
        const json header = {{"type", "frame"},
                             {"camera", camera},
                             {"frame", image->metadata().frame_index},
                             {"time", image->metadata().time},
                             {"width", bgr.cols},
                             {"height", bgr.rows},
                             {"overlay", true},
                             {"exposure_s", image->metadata().exposure_s},
                             {"gain_db", image->metadata().gain_db},
                             {"focus_m", image->metadata().focus_m}};
        Conform(protocol::CheckFrameHeader(header));
        server_->PublishFrame(camera, header,
                              std::make_shared<const std::string>(jpeg.begin(), jpeg.end()));
      }
      ++frames_encoded_;
      std::lock_guard lock(encode_mutex_);
      encode_walls_.push_back(WallNow());
      if (encode_walls_.size() > 26) encode_walls_.erase(encode_walls_.begin());
    } catch (const std::exception& error) {
      server_->Broadcast(Event("error", error.what()));
    }
  }
}

}  // namespace saccade::gui
