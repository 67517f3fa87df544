#pragma once
// The browser GUI of a running pipeline (issue 6): serves the page (web/public), the scene's
// meshes and textures, and speaks docs/gui-protocol.md over the server module: the state after
// every step, both eyes' annotated images as JPEG, and the commands (joints, fixate, effects,
// perception, pause, step, speed, stop, estop, clear), and the map of a pipeline with a
// mapping.map output (the `map` message: when it changed, at most every
// protocol::kMapEverySteps steps, at most protocol::kMaxMapPoints points).
//
// Threads: commands arrive on the server's I/O thread; they are checked there (joint limits,
// reachability, well-formed values: a bad one gets an error reply and changes nothing) and
// queued; AfterStep applies them on the simulation thread, between steps, where the
// components live, and so does WhileWaiting, while a step waits for its camera frames (the
// state the page then gets shows the command's targets a render sooner). JPEG encoding runs on a
// thread of its own that always takes the newest images, so that a slow encoder or client costs
// frames, never simulation steps.

#include <atomic>
#include <condition_variable>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "saccade/components/demo/overlay.h"
#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/render/renderer.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/run_control.h"
#include "saccade/scene/scene.h"
#include "saccade/server/gui_server.h"

namespace saccade::gui {

// What the loop said in a step, and its annotated eye views: the demo module's (components/demo/).
using components::JointStateMessage;
using components::demo::Annotate;
using components::demo::Latest;
using components::demo::Tap;

/// A recording the session writes (the page's Record button, the `record` command): the program
/// makes it (app: an MCAP file, record/recorder.h), the session calls it after each step and
/// closes it when asked, all on the simulation thread between steps.
class GuiRecording {
 public:
  virtual ~GuiRecording() = default;
  virtual void AfterStep(const runtime::StepContext& context) = 0;
  /// Closes the file; a line for the terminal.
  virtual std::string Close() = 0;
  virtual std::string file() const = 0;
  virtual uint64_t bytes() const = 0;
};

struct GuiOptions {
  std::string listen = "127.0.0.1";
  int port = 8080;
  std::string token;      ///< "" (and no no_token): a random one, printed in the address
  bool no_token = false;  ///< loopback only: serve without a token
  std::vector<std::string> allowed_hosts;  ///< Host names accepted besides loopback/listen
  std::string mode = "demo";               ///< "demo" or "gui", told to the page
  bool perception = true;                  ///< the loop commands the head at start
  bool paused = false;
  double speed = 1.0;  ///< simulated seconds per wall second at most
  int jpeg_quality = 80;
  /// The page's folder: public/ (index.html, app/) and node_modules/three.
  std::string web_dir = "web";
  /// Starts a recording of the pipeline (a new file each time): the `record` command. Empty:
  /// the command is refused. Throws saccade::Error when it cannot (the page is told).
  std::function<std::shared_ptr<GuiRecording>()> start_recording;
  /// A recording running from the start (`--record FILE.mcap`), which the page can stop.
  std::shared_ptr<GuiRecording> recording;
};

class GuiSession {
 public:
  /// Starts the server (throws Error when it cannot listen). `scene` must outlive the session.
  GuiSession(runtime::Pipeline& pipeline, const scene::Scene& scene, const std::string& scene_name,
             const GuiOptions& options);
  ~GuiSession();

  std::string url() const { return server_->url(); }

  /// On the simulation thread after each step: applies the queued commands, publishes the
  /// state and the images, keeps the pace (speed) and waits while paused. Returns when the
  /// next step may run or `stop` is set.
  void AfterStep(const runtime::StepContext& context, const Latest& latest,
                 const std::atomic<bool>& stop);

  /// On the simulation thread while a step waits on a device (runtime::RunOptions::
  /// while_waiting): applies the queued commands, and when there were any publishes the state
  /// (the last step's, with the commands' targets).
  void WhileWaiting();
  /// One line for the terminal: clients, frames sent and skipped.
  std::string Describe() const;

 private:
  // The commands (docs/gui-protocol.md): Handle checks each against the protocol's table
  // (gui/protocol.h) and hands it to its handler, on the I/O thread; a handler checks what the
  // table cannot (the joints' limits, reachability) and queues the work.
  using CommandFn = nlohmann::json (GuiSession::*)(const nlohmann::json& command);
  static const std::map<std::string, CommandFn>& CommandTable();
  static void CheckCommandTable();  // throws Error unless it and the table name the same
  nlohmann::json Handle(const nlohmann::json& command, int64_t client);
  nlohmann::json OnJoints(const nlohmann::json& command);
  nlohmann::json OnFixate(const nlohmann::json& command);
  nlohmann::json OnPerception(const nlohmann::json& command);
  nlohmann::json OnEffects(const nlohmann::json& command);
  nlohmann::json OnPause(const nlohmann::json& command);
  nlohmann::json OnResume(const nlohmann::json& command);
  nlohmann::json OnStep(const nlohmann::json& command);
  nlohmann::json OnSpeed(const nlohmann::json& command);
  nlohmann::json OnRecord(const nlohmann::json& command);
  nlohmann::json OnHeadStop(const nlohmann::json& command);  // stop, estop, clear
  nlohmann::json OnPing(const nlohmann::json& command);
  const head::HeadModel& RequireHead(const std::string& type) const;
  // Sets the targets, queues the motion (perception off) and completes `reply` with them.
  nlohmann::json MoveTo(const head::JointState& target, nlohmann::json reply);
  void Enqueue(std::function<void()> action);
  int ApplyQueued();  // how many commands it applied
  nlohmann::json StateJson(const runtime::StepContext& context, const Latest& latest);
  void EncodeLoop();
  // Sends the newest map when there is one the page has not had, and `step` is at least
  // kMapEverySteps after the last sent (or `now`: paused, the steps may not come).
  void PublishMap(int64_t step, bool now);
  void TapMap(runtime::Pipeline& pipeline);  // the first mapping.map output, when there is one
  head::JointState CurrentTargets() const;
  void SetPerception(bool enabled);  // simulation thread

  const scene::Scene& scene_;
  GuiOptions options_;
  runtime::RunControl control_;  // pause, steps, speed (set by commands, obeyed in AfterStep)
  std::unique_ptr<server::GuiServer> server_;

  // The components the GUI drives (nullptr when the pipeline has none).
  components::HeadRole* head_ = nullptr;  // the robot's roles (components/roles.h)
  components::EyeCamerasRole* cameras_ = nullptr;
  bool rendered_ = false;  // the cameras are rendered: effects exist
  std::vector<runtime::Component*> perception_components_;  // all but cameras and head
  bool hw_head_ = false;

  // Commands, from the I/O thread to the simulation thread.
  std::mutex queue_mutex_;
  std::vector<std::function<void()>> queue_;

  // Simulation-thread state, mirrored in atomics for the handler's checks and replies.
  std::atomic<double> sim_time_{0.0};
  std::atomic<bool> perception_{true};
  std::mutex effects_mutex_;
  render::RendererOptions effects_;  // as last asked (effects_mutex_)
  nlohmann::json head_status_;       // hw.head's newest status, null without one
  // The head's state as a hand command left it (its reply: the new targets), newer than the
  // last step's until the next step ends; the states published meanwhile show it.
  std::optional<JointStateMessage> commanded_;
  mutable std::mutex joints_mutex_;
  head::JointState targets_;  // the latest targets, for partial joint commands (joints_mutex_)

  // The newest map of the pipeline's first mapping.map output (emitted on any thread), whether
  // the page has had it, and the step it was last sent at.
  std::mutex map_mutex_;
  std::shared_ptr<const components::MapMessage> map_;
  bool map_pending_ = false;
  int64_t map_sent_step_ = std::numeric_limits<int64_t>::min() / 2;

  // The recording (simulation thread) and what the state says of it.
  std::shared_ptr<GuiRecording> recording_;
  std::mutex recording_mutex_;
  nlohmann::json recording_json_;  // {file, megabytes} or null (recording_mutex_)

  // The last step AfterStep saw (simulation thread), for the states WhileWaiting publishes.
  std::optional<runtime::StepContext> last_context_;
  const Latest* last_latest_ = nullptr;
  // Pacing and timing (simulation thread).
  double last_return_wall_ = -1.0;
  double last_step_ms_ = 0.0;
  std::vector<double> step_walls_;  // recent AfterStep times, for steps per second
  int64_t last_frame_sent_ = -1;

  // The encoder thread and its one-slot mailbox.
  std::thread encoder_;
  std::mutex encode_mutex_;
  std::condition_variable encode_cv_;
  std::optional<Latest> to_encode_;
  bool encoder_stop_ = false;
  std::atomic<int64_t> frames_encoded_{0};
  std::vector<double> encode_walls_;  // encoder thread (encode_mutex_)
};

}  // namespace saccade::gui
