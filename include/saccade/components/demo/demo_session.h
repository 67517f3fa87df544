#pragma once
// The demo (`saccade demo`, and `saccade gui`, which runs it with perception off): the
// active-vision loop of a pipeline file (seed section 6; pipelines/demo.yaml) on its robot,
// every fixation scored against the scene's ground truth (fixation_scoring.h), the loop's
// latency measured (summary.h) and, optionally, the annotated frames recorded (recording.h).
//
// The program parses its command line into DemoOptions, registers its topic transport, builds
// a DemoSession, attaches the browser GUI to its pipeline when it has one, runs it, and prints
// the DemoSummary:
//
//   DemoSession session(options, print_line);
//   std::atomic<bool> stop{false};      // set by Ctrl-C
//   const DemoSummary summary = session.Run(stop, {});
//   std::cout << summary.FullReport();
//
// Threads: one. The session's pipeline runs on the thread that calls Run; `stop` may be set
// from any thread or a signal handler.

#include <atomic>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "saccade/components/demo/loop_outputs.h"
#include "saccade/components/demo/summary.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "saccade/scene/scene.h"

namespace saccade::components::demo {

/// What the demo runs, for how long, and what it records.
struct DemoOptions {
  std::string pipeline;     ///< the pipeline file (components and connections)
  std::string scene;        ///< a scene replacing the pipeline's; empty: the pipeline's
  std::string hardware;     ///< a hardware file replacing the pipeline's; empty: its own
  std::string head;         ///< a head file replacing the scene's head; empty: the scene's
  double duration = 40.0;   ///< s, > 0: the longest run on the loop's clock (wall s with realtime)
  std::string record;       ///< a folder for the recording (recording.h); empty: none
  bool force = false;       ///< replace an earlier recording in `record`
  bool realtime = false;    ///< run on the wall clock at the pipeline's rate
  bool keep_going = false;  ///< continue after a component fails (on_error: continue)
  /// A front end (the browser GUI) paces the loop through RunHooks: it runs until stopped,
  /// with no duration, and does not end once every face was fixated.
  bool live = false;
  /// Entries that replace those of the pipeline's `transport:` map (the --dds-* options).
  nlohmann::json transport = nlohmann::json::object();

  /// False, with the reason in `error`, when an option is out of range.
  bool IsValid(std::string* error) const;
};

/// What the program adds to the loop; each may be left empty.
struct RunHooks {
  /// A step failed (the loop goes on or stops as the pipeline's on_error says).
  std::function<void(const runtime::StepError&)> on_error;
  /// With DemoOptions::live: while a step waits for its frames (runtime::RunOptions::
  /// while_waiting) ...
  std::function<void()> while_waiting;
  /// ... and after every step, with what the loop said in it; returns when the next step may
  /// run or `stop` is set (gui::GuiSession::AfterStep).
  std::function<void(const runtime::StepContext&, const Latest&, const std::atomic<bool>& stop)>
      after_step;
};

class DemoSession {
 public:
  /// A line for people as the loop goes: each fixation as it arrives, a head fault, and that
  /// real cameras give no ground truth. Empty: nothing is said (--json).
  using Progress = std::function<void(const std::string& line)>;

  /// Loads the pipeline file (with the options' scene, hardware and transport) and builds it,
  /// finds the robot by its roles (components/roles.h) and taps the loop's outputs. The
  /// pipeline's topic transport, if it uses one, must be registered first. Throws
  /// InvalidArgument when the options are not valid or the pipeline has no eye cameras, and
  /// what runtime::LoadPipelineFile and runtime::Pipeline::Build throw.
  DemoSession(const DemoOptions& options, Progress progress);
  ~DemoSession();
  DemoSession(const DemoSession&) = delete;
  DemoSession& operator=(const DemoSession&) = delete;

  /// The built pipeline, for a front end to attach to before Run.
  runtime::Pipeline& pipeline();
  /// The scene the cameras see; with real cameras, the one that only carries the robot.
  const scene::Scene& scene() const;

  /// Runs the loop until the duration is over, every face has been fixated and let go (which
  /// sets `stop`; not when live), or `stop` is set. Opens the recording first (throws
  /// InvalidArgument when its folder holds one and the options do not force), writes a frame
  /// per step and summary.json at the end. Once per session.
  DemoSummary Run(std::atomic<bool>& stop, const RunHooks& hooks);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saccade::components::demo
