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
#include "saccade/core/error.h"
#include "saccade/geometry/json.h"
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

constexpr double kRadToDeg = 180.0 / M_PI;

double WallNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// The value of a number field, finite; CommandError naming the command and the field.
double FiniteNumber(const json& value, const std::string& where) {
  if (!value.is_number()) throw CommandError(where + ": expected a number, got " + value.dump());
  const double x = value.get<double>();
  if (!std::isfinite(x)) throw CommandError(where + ": expected a finite number");
  return x;
}

bool Flag(const json& command, const std::string& field, bool current) {
  if (!command.contains(field)) return current;
  if (!command[field].is_boolean()) {
    throw CommandError(command["type"].get<std::string>() + ": " + field +
                       " must be true or false, got " + command[field].dump());
  }
  return command[field].get<bool>();
}

double AxisErrorDeg(const geometry::Pose& X_WC, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d to = (p_W - X_WC.translation()).normalized();
  return std::acos(std::clamp(X_WC.linear().col(2).dot(to), -1.0, 1.0)) * kRadToDeg;
}

}  // namespace

GuiSession::GuiSession(runtime::Pipeline& pipeline, const scene::Scene& scene,
                       const std::string& scene_name, const GuiOptions& options)
    : scene_(scene), options_(options), control_(options.paused) {
  perception_ = options.perception;
  if (!(options.speed >= 0.05 && options.speed <= 10.0)) {
    throw InvalidArgument(fmt::format("--speed must be in [0.05, 10], got {}", options.speed));
  }
  control_.SetSpeed(options.speed);
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
      server_->Broadcast({{"type", "event"}, {"level", "error"}, {"message", error.what()}});
    }
  }
  return static_cast<int>(actions.size());
}

void GuiSession::SetPerception(bool enabled) {
  for (runtime::Component* c : perception_components_) c->SetEnabled(enabled);
  perception_ = enabled;
}

json GuiSession::Handle(const json& command, int64_t client) {
  (void)client;
  const std::string type = command["type"].get<std::string>();
  if (type == "ping") return {{"time", sim_time_.load()}};
  if (type == "joints" || type == "fixate") {
    if (!head_ || !scene_.robot()) throw CommandError(type + ": this pipeline has no head to move");
    const head::HeadDescription& head = scene_.robot()->head;
    head::JointState target = CurrentTargets();
    json reply;
    if (type == "joints") {
      if (!command.contains("positions") || !command["positions"].is_object() ||
          command["positions"].empty()) {
        throw CommandError("joints: expected positions: {pan, tilt, left, right or vergence: rad}");
      }
      for (const auto& [name, value] : command["positions"].items()) {
        const double x = FiniteNumber(value, "joints: " + name);
        if (name == "vergence") {
          // Symmetric vergence (seed appendix A): > 0 converges, the left eye turning right.
          target.left = -x;
          target.right = x;
          continue;
        }
        bool known = false;
        for (head::Joint j : head::kAllJoints) {
          if (name == head::JointName(j)) {
            target[j] = x;
            known = true;
          }
        }
        if (!known) {
          throw CommandError("joints: unknown joint '" + name +
                             "' (pan, tilt, left, right or vergence)");
        }
      }
      // The server's check (docs/gui-protocol.md): a value outside the limits rejects the
      // whole command; the page's clamping is a convenience, never the safety.
      for (head::Joint j : head::kAllJoints) {
        const head::JointLimits& l = head.limits(j);
        if (!l.Contains(target[j])) {
          throw CommandError(fmt::format(
              "joints: {} {:.4f} rad ({:.2f} deg) is outside its limits [{:.4f}, {:.4f}] rad",
              head::JointName(j), target[j], target[j] * kRadToDeg, l.min, l.max));
        }
      }
      reply = {{"targets", ToJson(target)}};
    } else {
      const json& p = command.contains("p_W") ? command["p_W"] : json();
      if (!p.is_array() || p.size() != 3) {
        throw CommandError("fixate: expected p_W: [x, y, z] (metres, world frame), got " +
                           p.dump());
      }
      const Eigen::Vector3d p_W(FiniteNumber(p[0], "fixate: p_W[0]"),
                                FiniteNumber(p[1], "fixate: p_W[1]"),
                                FiniteNumber(p[2], "fixate: p_W[2]"));
      head::IkOptions ik;
      ik.seed = target;
      const head::IkResult solution = head::SolveFixation(head, p_W, ik);
      if (!solution.reachable()) {
        throw CommandError(fmt::format("fixate: [{:.3f}, {:.3f}, {:.3f}] cannot be fixated: {}",
                                       p_W.x(), p_W.y(), p_W.z(), solution.message));
      }
      target = solution.joints;
      reply = {{"targets", ToJson(target)}, {"axis_error_deg", solution.axis_error * kRadToDeg}};
    }
    {
      std::lock_guard lock(joints_mutex_);
      targets_ = target;
    }
    Enqueue([this, target] {
      SetPerception(false);  // the hand overrides the loop
      JointCommand c;
      c.time = sim_time_;
      c.positions = target;
      c.velocities = {0.0, 0.0, 0.0, 0.0};
      commanded_ = head_->Move(c);
    });
    reply["perception"] = false;
    return reply;
  }
  if (type == "perception") {
    if (perception_components_.empty()) {
      throw CommandError("perception: this pipeline has no components besides the robot");
    }
    const bool enabled = Flag(command, "enabled", perception_);
    Enqueue([this, enabled] { SetPerception(enabled); });
    return {{"perception", enabled}};
  }
  if (type == "effects") {
    if (!rendered_) {
      throw CommandError("effects: the cameras are not simulated: they have no effects to switch");
    }
    for (const auto& [name, value] : command.items()) {
      if (name != "type" && name != "id" && name != "distortion" && name != "noise" &&
          name != "motion_blur") {
        throw CommandError("effects: unknown field '" + name +
                           "' (distortion, noise, motion_blur)");
      }
    }
    std::lock_guard lock(effects_mutex_);
    const bool d = Flag(command, "distortion", effects_.distortion);
    const bool n = Flag(command, "noise", effects_.noise);
    const bool b = Flag(command, "motion_blur", effects_.motion_blur);
    effects_.distortion = d;
    effects_.noise = n;
    effects_.motion_blur = b;
    Enqueue([this, d, n, b] { cameras_->SetEffects(d, n, b); });
    return {{"effects", {{"distortion", d}, {"noise", n}, {"motion_blur", b}}}};
  }
  if (type == "pause") {
    control_.Pause();
    return {{"paused", true}};
  }
  if (type == "resume") {
    control_.Resume();
    return {{"paused", false}};
  }
  if (type == "step") {
    int count = 1;
    if (command.contains("count")) {
      if (!command["count"].is_number_integer() || command["count"].get<int64_t>() < 1 ||
          command["count"].get<int64_t>() > 1000) {
        throw CommandError("step: count must be an integer in [1, 1000], got " +
                           command["count"].dump());
      }
      count = command["count"].get<int>();
    }
    if (!control_.paused()) {
      throw CommandError("step: pause first (steps are for a paused simulation)");
    }
    control_.Step(count);
    return {{"steps", count}};
  }
  if (type == "speed") {
    const double factor = command.contains("factor")
                              ? FiniteNumber(command["factor"], "speed: factor")
                              : std::nan("");
    if (!(factor >= 0.05 && factor <= 10.0)) {
      throw CommandError("speed: factor must be in [0.05, 10] (simulated s per wall s), got " +
                         (command.contains("factor") ? command["factor"].dump() : "nothing"));
    }
    control_.SetSpeed(factor);
    return {{"speed", factor}};
  }
  if (type == "stop" || type == "estop" || type == "clear") {
    if (!head_) throw CommandError(type + ": this pipeline has no head");
    if ((type == "estop" || type == "clear") && !hw_head_) {
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
  throw CommandError("unknown command type '" + type +
                     "' (joints, fixate, perception, effects, pause, resume, step, speed, stop, "
                     "estop, clear, ping, frame_window, frame_ack: docs/gui-protocol.md)");
}

json GuiSession::StateJson(const runtime::StepContext& context, const Latest& latest) {
  const double t = context.time + context.dt;  // the state after this step
  json state = {{"type", "state"},
                {"step", context.step},
                {"time", t},
                {"paused", control_.paused()},
                {"speed", control_.speed()},
                {"perception", perception_.load()},
                {"manual", !perception_.load()}};
  if (rendered_) {
    const render::RendererOptions& o = *cameras_->rendered();
    state["effects"] = {
        {"distortion", o.distortion}, {"noise", o.noise}, {"motion_blur", o.motion_blur}};
  } else {
    state["effects"] = nullptr;
  }
  std::optional<head::HeadFrames> frames;
  const std::optional<JointStateMessage>& joints = commanded_ ? commanded_ : latest.joints;
  if (joints && scene_.robot()) {
    const JointStateMessage& j = *joints;
    state["joints"] = {{"positions", ToJson(j.positions)},
                       {"targets", ToJson(j.targets)},
                       {"velocities", ToJson(j.velocities)},
                       {"arrived", j.arrived}};
    frames = head::ForwardKinematics(scene_.robot()->head, j.positions);
    state["frames"] = internal::FramesJson(*frames);
    state["fixation_W"] = frames->p_WFixation ? ToJson(*frames->p_WFixation) : json(nullptr);
    std::lock_guard lock(joints_mutex_);
    if (perception_) targets_ = j.targets;  // partial hand commands start from here
  } else {
    state["joints"] = nullptr;
    state["frames"] = nullptr;
    state["fixation_W"] = nullptr;
  }
  if (perception_ && latest.target && latest.target->valid) {
    state["target"] = {
        {"valid", true}, {"p_W", ToJson(latest.target->p_W)}, {"id", latest.target->target_id}};
    if (frames) {
      state["fixation_error_deg"] = {
          {"left", AxisErrorDeg(frames->X_WCamLeft, latest.target->p_W)},
          {"right", AxisErrorDeg(frames->X_WCamRight, latest.target->p_W)}};
    } else {
      state["fixation_error_deg"] = nullptr;
    }
  } else {
    state["target"] = nullptr;
    state["fixation_error_deg"] = nullptr;
  }
  state["objects"] = internal::MovingObjectsJson(scene_, t);
  const double now = WallNow();
  double steps_per_s = 0.0, frames_per_s = 0.0;
  if (step_walls_.size() >= 2) {
    steps_per_s =
        (step_walls_.size() - 1) / std::max(1e-9, step_walls_.back() - step_walls_.front());
  }
  {
    std::lock_guard lock(encode_mutex_);
    if (encode_walls_.size() >= 2 && now - encode_walls_.back() < 2.0) {
      frames_per_s =
          (encode_walls_.size() - 1) / std::max(1e-9, encode_walls_.back() - encode_walls_.front());
    }
  }
  state["timing"] = {{"step_ms", last_step_ms_},
                     {"steps_per_s", steps_per_s},
                     {"realtime_factor", steps_per_s * context.dt},
                     {"frames_per_s", frames_per_s}};
  state["head_status"] = head_status_;
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
  last_context_ = context;
  last_context_->while_waiting = nullptr;
  last_latest_ = &latest;
  ApplyQueued();
  server_->PublishState(StateJson(context, latest));

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
    }
  });
  last_return_wall_ = WallNow();
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
                             {"overlay", true}};
        server_->PublishFrame(camera, header,
                              std::make_shared<const std::string>(jpeg.begin(), jpeg.end()));
      }
      ++frames_encoded_;
      std::lock_guard lock(encode_mutex_);
      encode_walls_.push_back(WallNow());
      if (encode_walls_.size() > 26) encode_walls_.erase(encode_walls_.begin());
    } catch (const std::exception& error) {
      server_->Broadcast({{"type", "event"}, {"level", "error"}, {"message", error.what()}});
    }
  }
}

}  // namespace saccade::gui
