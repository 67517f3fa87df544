// demo and gui: the command lines of the demo module (components/demo/demo_session.h), the
// active-vision loop (seed section 6) with a report of every fixation against the scene's
// ground truth, the loop's latency and, optionally, a recording of the annotated frames. Here
// only the options, the terminal, the signals and the browser GUI are wired to it.

#include <fmt/format.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.h"
#include "saccade/components/demo/demo_session.h"
#include "saccade/components/register.h"
#include "saccade/dds/transport.h"
#include "saccade/gui/protocol.h"
#include "saccade/gui/session.h"
#include "saccade/runtime/component_reference.h"

namespace saccade::app {
namespace {

namespace fs = std::filesystem;
using components::demo::DemoSession;
using components::demo::DemoSummary;
using gui::GuiSession;

std::atomic<bool> g_stop{false};
extern "C" void OnDemoInterrupt(int) { g_stop = true; }

/// The demo's defaults: pipelines/demo.yaml.
components::demo::DemoOptions DefaultDemo() {
  components::demo::DemoOptions demo;
  demo.pipeline = ShippedFile("pipelines/demo.yaml");
  return demo;
}

struct Options {
  components::demo::DemoOptions demo = DefaultDemo();
  bool json = false;
  bool list = false;
  bool markdown = false;
  bool gui = false;
  bool dds = false;  // gui --dds: pipelines/remote.yaml unless --pipeline names another
  DdsOverrides dds_overrides;
  gui::GuiOptions gui_options;
  McapOptions record;            // --record FILE.mcap (a folder name: DemoOptions::record)
  std::string record_dir = ".";  // the page's Record button writes here
};

/// A recording the GUI holds (gui::GuiRecording): the page starts and stops it.
class GuiMcapRecording final : public gui::GuiRecording {
 public:
  GuiMcapRecording(const McapOptions& o, runtime::Pipeline& pipeline,
                   std::map<std::string, std::string> metadata)
      : recording_(o, pipeline, std::move(metadata)) {}
  void AfterStep(const runtime::StepContext& context) override { recording_.AfterStep(context); }
  std::string Close() override { return recording_.Close(); }
  std::string file() const override { return recording_.file(); }
  uint64_t bytes() const override { return recording_.bytes(); }

 private:
  Recording recording_;
};

/// A new file in `dir` for the page's Record button: saccade-YYYYMMDD-HHMMSS[-N].mcap.
std::string NewRecordingFile(const std::string& dir) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
  fs::path file = fs::path(dir) / fmt::format("saccade-{}.mcap", stamp);
  for (int n = 2; fs::exists(file); ++n) {
    file = fs::path(dir) / fmt::format("saccade-{}-{}.mcap", stamp, n);
  }
  return file.string();
}

/// --list-components: the component types, as text, JSON or docs/components.md.
int ListComponents(const Options& o) {
  const auto reference = runtime::DescribeComponents(runtime::ComponentRegistry::Global());
  fmt::print("{}", o.json       ? runtime::ComponentsJson(reference).dump(2) + "\n"
                   : o.markdown ? runtime::ComponentsMarkdown(reference)
                                : runtime::ComponentsText(reference));
  return 0;
}

/// The browser GUI on the session's pipeline (demo --gui, gui).
std::unique_ptr<GuiSession> ServeGui(Options& o, DemoSession& session) {
  o.gui_options.web_dir = ShippedFile("web");
  const std::string scene_name =
      o.demo.scene.empty() ? fs::path(o.demo.pipeline).filename().string() : o.demo.scene;
  auto gui =
      std::make_unique<GuiSession>(session.pipeline(), session.scene(), scene_name, o.gui_options);
  fmt::print("gui: serving {}  (open it in a browser; Ctrl-C to stop)\n", gui->url());
  std::fflush(stdout);
  return gui;
}

/// The demo's loop until it ends or Ctrl-C (or SIGTERM).
DemoSummary RunUntilDone(DemoSession& session, GuiSession* gui, Recording* recording) {
  components::demo::RunHooks hooks;
  hooks.on_error = [](const runtime::StepError& error) {
    fmt::print(stderr, "saccade: error: {}\n", error.ToString());
  };
  if (gui != nullptr) hooks.while_waiting = [gui] { gui->WhileWaiting(); };
  if (gui != nullptr || recording != nullptr) {
    hooks.after_step = [gui, recording](const runtime::StepContext& context,
                                        const components::demo::Latest& latest,
                                        const std::atomic<bool>& stop) {
      if (recording != nullptr) recording->AfterStep(context);
      if (gui != nullptr) gui->AfterStep(context, latest, stop);
    };
  }
  g_stop = false;
  auto previous_int = std::signal(SIGINT, OnDemoInterrupt);
  auto previous_term = std::signal(SIGTERM, OnDemoInterrupt);
  DemoSummary summary = session.Run(g_stop, hooks);
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  return summary;
}

/// `demo` and `gui`: the demo module (components/demo/demo_session.h) wired to the terminal,
/// the signals and, with --gui, the browser GUI.
int RunDemo(Options o) {
  components::RegisterComponents();
  if (o.list) return ListComponents(o);
  // Topic connections (pipelines/remote.yaml, or any file with topics) go over DDS.
  dds::RegisterDdsTransport(runtime::ComponentRegistry::Global());
  o.demo.transport = DdsTransport(o.dds_overrides);
  o.demo.live = o.gui;
  if (IsMcapPath(o.demo.record)) {
    o.record.path = o.demo.record;
    o.record.force = o.demo.force;
    o.demo.record.clear();
  }
  DemoSession::Progress progress;
  if (!o.json) {
    progress = [](const std::string& line) {
      fmt::print("{}", line);
      std::fflush(stdout);
    };
  }
  DemoSession session(o.demo, progress);
  const auto metadata = RunMetadata(o.gui ? "gui" : "demo", o.demo.pipeline, o.demo.scene,
                                    o.demo.head, o.demo.hardware);
  std::unique_ptr<Recording> recording;
  if (o.gui) {
    // The GUI holds the recordings, so that the page can stop and start them.
    if (!o.record.path.empty()) {
      o.gui_options.recording =
          std::make_shared<GuiMcapRecording>(o.record, session.pipeline(), metadata);
    }
    o.gui_options.start_recording = [&o, &session, metadata] {
      McapOptions file = o.record;
      file.path = NewRecordingFile(o.record_dir);
      return std::make_shared<GuiMcapRecording>(file, session.pipeline(), metadata);
    };
  } else if (!o.record.path.empty()) {
    recording = std::make_unique<Recording>(o.record, session.pipeline(), metadata);
  }
  std::unique_ptr<GuiSession> gui;
  if (o.gui) gui = ServeGui(o, session);
  const DemoSummary summary = RunUntilDone(session, gui.get(), recording.get());
  if (recording) {
    const std::string line = recording->Close();
    if (!o.json) fmt::print("{}", line);
  }

  if (o.json) {
    fmt::print("{}\n", summary.Json().dump(2));
  } else if (!summary.nothing_ran()) {
    // Nothing ran: the error, printed above, is the whole story for people (the JSON and
    // summary.json keep it).
    fmt::print("{}", summary.FullReport());
  }
  if (gui) fmt::print("{}\n", gui->Describe());
  if (!summary.run.errors.empty() && summary.run.stopped_on_error) return 1;
  if (summary.faces_fixated == 0 && !o.gui) {
    fmt::print(stderr, "saccade: demo: no face was fixated\n");
    return 3;
  }
  return 0;
}

/// The options that serve the browser GUI, shared by `demo --gui` and `gui`.
void AddGuiOptions(CLI::App* command, Options& o) {
  command
      ->add_option("--listen", o.gui_options.listen,
                   "Address the GUI listens on; off loopback (127.0.0.1, ::1) a token is "
                   "required, so --no-token is refused")
      ->capture_default_str();
  command->add_option("--port", o.gui_options.port, "TCP port of the GUI (0: any free port)")
      ->capture_default_str();
  command->add_option(
      "--token", o.gui_options.token,
      "Access token the page and scripts must present (it is in the printed "
      "address); default: $SACCADE_GUI_TOKEN, else a random one per run on loopback. "
      "Required with a non-loopback --listen");
  command->add_flag("--no-token", o.gui_options.no_token,
                    "Serve without a token (loopback --listen only): any local program, and any "
                    "page from this server, may then drive the head");
  command->add_option("--allow-host", o.gui_options.allowed_hosts,
                      "A host name the browser may use for this server besides localhost, "
                      "loopback addresses and the --listen address (e.g. robot-head.local); "
                      "repeatable. Other Host headers get 403 (DNS rebinding)");
  command
      ->add_option("--speed", o.gui_options.speed,
                   "Simulated seconds per wall second, at most (0.05 .. 10; the page changes it)")
      ->capture_default_str();
  command->add_flag("--paused", o.gui_options.paused,
                    "Start paused (the page's Resume and Step buttons run it)");
  command
      ->add_option("--record-dir", o.record_dir,
                   "Folder of the recordings the page's Record button starts "
                   "(saccade-YYYYMMDD-HHMMSS.mcap, every topic in MCAP)")
      ->check(CLI::ExistingDirectory)
      ->capture_default_str();
}

}  // namespace

Runner AddGuiCommand(CLI::App& app) {
  auto o = std::make_shared<Options>();
  o->gui = true;
  o->gui_options.mode = "gui";
  o->gui_options.perception = false;
  auto* gui = app.add_subcommand(
      "gui",
      "The browser GUI on a scene: serves a page (three.js) showing the 3D world, the head, "
      "both camera frustums with their live images, and lets you drag a joint (direct "
      "kinematics), click a point to fixate (inverse kinematics), switch effects and the "
      "perception loop, pause, step and change the speed. Prints the page's address and runs "
      "until Ctrl-C. The protocol (also for scripts): docs/gui-protocol.md. Perception starts "
      "off; `saccade demo --gui` starts with it on.");
  gui->add_option("--scene", o->demo.scene,
                  "Scene YAML (default: the demo's, scenes/portraits.yaml)")
      ->check(CLI::ExistingFile);
  gui->add_option("--head", o->demo.head,
                  "Head file (robots/*.yaml) in place of the scene's robot head, at its home "
                  "joints: any head, e.g. robots/humanoid.yaml")
      ->check(CLI::ExistingFile);
  gui->add_option("--pipeline", o->demo.pipeline, "Pipeline YAML (default: the demo's)")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  auto* pipeline_option = gui->get_option("--pipeline");
  gui->add_option("--hardware", o->demo.hardware,
                  "Hardware file (pipelines/hardware/): the GUI drives the real head too")
      ->check(CLI::ExistingFile);
  gui->add_flag("--dds", o->dds,
                "Attach to a robot running in another process or on another machine, over DDS "
                "(pipelines/remote.yaml: its images and joint states in, the GUI's commands "
                "out; start the robot with `saccade run pipelines/robot.yaml --realtime "
                "--steps 0`, with the same --scene and DDS domain)")
      ->excludes("--hardware");
  AddDdsOptions(gui, o->dds_overrides);
  AddGuiOptions(gui, *o);
  gui->add_option("--record", o->record.path,
                  "Record every topic of the session to this MCAP file (ROS 2 messages and "
                  "JSON, with the ground truth), until Ctrl-C");
  gui->add_flag("--force", o->record.force, "Replace an existing --record file");
  AddRecordTuning(gui, o->record);
  // The protocol's table (gui/protocol.h) as its generated files; nothing is served.
  auto protocol_markdown = std::make_shared<bool>(false);
  auto protocol_js = std::make_shared<bool>(false);
  gui->add_flag("--protocol-markdown", *protocol_markdown,
                "Print the protocol, docs/gui-protocol.md, and exit");
  gui->add_flag("--protocol-js", *protocol_js,
                "Print the page's copy of the protocol, web/public/app/protocol.js, and exit")
      ->excludes("--protocol-markdown");
  return [o, pipeline_option, protocol_markdown, protocol_js] {
    if (*protocol_markdown || *protocol_js) {
      fmt::print("{}", *protocol_js ? gui::protocol::JavaScript() : gui::protocol::Markdown());
      return 0;
    }
    if (o->dds && pipeline_option->count() == 0) {
      o->demo.pipeline = ShippedFile("pipelines/remote.yaml");
    }
    return RunDemo(*o);
  };
}

Runner AddDemoCommand(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* demo = app.add_subcommand(
      "demo",
      "The main job, the active-vision loop of the seed paper, headless: the head (POPEYE, or "
      "any head with --head) finds "
      "the faces on the scene's portraits (rejecting the cat), tracks each with CamShift, "
      "triangulates it and fixates it, closest first, moving on once inhibition of return "
      "suppresses it. Prints each fixation's object, 3D error against the true face centre, "
      "each eye's angular error as it began and the time it took; at the end each eye's "
      "largest error over each fixation, then the latency of every stage. "
      "Exit status: 0 when at least one face was fixated, 3 when none was, 1 on an error.");
  demo->add_option("--pipeline", o->demo.pipeline, "Pipeline YAML (components and connections)")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  demo->add_option("--scene", o->demo.scene,
                   "Scene YAML; replaces every component's `scene` parameter (default: the "
                   "pipeline's, scenes/portraits.yaml; scenes/portraits_moving.yaml shows "
                   "smooth pursuit)")
      ->check(CLI::ExistingFile);
  demo->add_option("--head", o->demo.head,
                   "Head file (robots/*.yaml) in place of the scene's robot head, at its home "
                   "joints (robots/humanoid.yaml, robots/pan_tilt_vergence.yaml, ...; default: "
                   "the scene's, POPEYE)")
      ->check(CLI::ExistingFile);
  demo->add_option("--hardware", o->demo.hardware,
                   "Hardware file: which robot runs the loop, replacing the pipeline's "
                   "`hardware:` line (pipelines/hardware/: simulator.yaml, "
                   "recorded_cameras.yaml, emulated_servos.yaml, mirror.yaml, robot.yaml)")
      ->check(CLI::ExistingFile);
  demo->add_option("--duration", o->demo.duration,
                   "Longest run, in seconds of the loop's clock (simulated; wall seconds with "
                   "--realtime); it ends sooner once every face was fixated")
      ->capture_default_str();
  demo->add_option("--record", o->demo.record,
                   "FILE.mcap: every topic of the run in MCAP (ROS 2 messages and JSON, with "
                   "the ground truth; Foxglove, rosbag2, `saccade mcap info`). Any other name: "
                   "a folder for the annotated frames (frames/*.jpg), a video (demo.avi, "
                   "MJPEG), a PNG per fixation and summary.json");
  demo->add_flag("--force", o->demo.force, "Replace an earlier recording (--record)");
  AddRecordTuning(demo, o->record);
  demo->add_flag("--json", o->json, "Print the report as JSON (the same as summary.json)");
  demo->add_flag("--realtime", o->demo.realtime,
                 "Run on the wall clock at the pipeline's rate instead of simulated time");
  demo->add_flag("--keep-going", o->demo.keep_going,
                 "Continue after a component fails (the pipeline's on_error: continue)");
  demo->add_flag("--list-components", o->list,
                 "List the component types a pipeline can use: ports, methods and parameters "
                 "(with --json: as JSON; with --markdown: docs/components.md)");
  demo->add_flag("--markdown", o->markdown, "With --list-components: print it as Markdown");
  demo->add_flag("--gui", o->gui,
                 "Serve the browser GUI (prints its address) and run until Ctrl-C; see "
                 "`saccade gui --help`");
  AddGuiOptions(demo, *o);
  return [o] { return RunDemo(*o); };
}

}  // namespace saccade::app
