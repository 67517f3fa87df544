// demo: the active-vision loop (seed section 6) run headless on a scene, with a report of
// every fixation against the scene's ground truth, the loop's latency and, optionally, a
// recording of the annotated frames.

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/components/demo_report.h"
#include "saccade/components/fixation_scoring.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/components/roles.h"
#include "saccade/core/error.h"
#include "saccade/dds/transport.h"
#include "saccade/gui/overlay.h"
#include "saccade/gui/protocol.h"
#include "saccade/gui/recording.h"
#include "saccade/gui/session.h"
#include "saccade/runtime/component_reference.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "saccade/scene/scene.h"

namespace saccade::app {
namespace {

namespace fs = std::filesystem;
using components::HeadStatusMessage;
using gui::GuiSession;
using gui::Recorder;
using nlohmann::json;

std::atomic<bool> g_stop{false};
extern "C" void OnDemoInterrupt(int) { g_stop = true; }

struct Options {
  std::string pipeline = ShippedFile("pipelines/demo.yaml");
  std::string scene;
  std::string hardware;
  double duration = 40.0;
  std::string record;
  bool force = false;
  bool json = false;
  bool realtime = false;
  bool keep_going = false;
  bool list = false;
  bool markdown = false;
  bool gui = false;
  bool dds = false;  // gui --dds: pipelines/remote.yaml unless --pipeline names another
  DdsOverrides dds_overrides;
  gui::GuiOptions gui_options;
};

/// One attended target, from its selection to the end of its dwell.
int RunDemo(Options o) {
  components::RegisterComponents();
  if (o.list) {
    const auto reference = runtime::DescribeComponents(runtime::ComponentRegistry::Global());
    fmt::print("{}", o.json       ? runtime::ComponentsJson(reference).dump(2) + "\n"
                     : o.markdown ? runtime::ComponentsMarkdown(reference)
                                  : runtime::ComponentsText(reference));
    return 0;
  }
  if (!(o.duration > 0.0) || !std::isfinite(o.duration)) {
    throw InvalidArgument(fmt::format("demo: --duration must be > 0 s, got {}", o.duration));
  }
  // Topic connections (pipelines/remote.yaml, or any file with topics) go over DDS.
  dds::RegisterDdsTransport(runtime::ComponentRegistry::Global());
  runtime::PipelineSpec spec = runtime::LoadPipelineFile(o.pipeline, o.hardware);
  if (!o.scene.empty()) runtime::ReplaceScene(spec, o.scene, "--scene");
  ApplyDdsOverrides(o.dds_overrides, spec);
  if (o.keep_going) spec.on_error = runtime::OnError::kContinue;
  const double dt = spec.clock.step;
  if (o.realtime) {
    spec.clock.mode = runtime::ClockMode::kRealtime;
    spec.clock.rate_hz = 1.0 / dt;
  }
  runtime::Pipeline pipeline = runtime::Pipeline::Build(spec);

  // The robot by its roles (components/roles.h). Simulated cameras give ground truth; real
  // ones (hw.cameras) give none.
  std::string cameras_name, head_name;
  const components::EyeCamerasRole* cameras =
      pipeline.FindRole<components::EyeCamerasRole>(&cameras_name);
  if (!cameras) {
    throw InvalidArgument(
        "demo: pipeline " + o.pipeline +
        " has no eye cameras (a sim.cameras, hw.cameras or remote.cameras component)");
  }
  pipeline.FindRole<components::HeadRole>(&head_name);
  components::CaptureToCommand latency(spec, cameras_name, head_name);
  components::LoopFigures figures(pipeline);
  const bool truth = cameras->rendered() != nullptr;
  // Real cameras: the scene only carries the robot; its pictures are not what they see.
  const scene::Scene& scene = cameras->scene();
  components::FixationScorer scorer(scene, truth);
  const int faces_total = scorer.faces_total();
  if (!truth && !o.json) {
    for (const runtime::ComponentSpec& c : spec.components) {
      if (c.name == cameras_name) {
        fmt::print("real cameras ({}): no ground truth; fixations are reported as triangulated\n",
                   c.type);
      }
    }
  }

  components::Latest latest;
  components::TapLoopOutputs(pipeline, &latest);
  std::optional<HeadStatusMessage> head_status;
  components::Tap<HeadStatusMessage>(pipeline, [&](const HeadStatusMessage& m) {
    if (!o.json && m.fault != (head_status ? head_status->fault : "") && !m.fault.empty()) {
      fmt::print("t = {:6.2f} s  head FAULT: {}\n", m.time, m.fault);
    }
    head_status = m;
  });

  std::unique_ptr<GuiSession> gui;
  if (o.gui) {
    o.gui_options.web_dir = ShippedFile("web");
    gui = std::make_unique<GuiSession>(
        pipeline, scene, o.scene.empty() ? fs::path(o.pipeline).filename().string() : o.scene,
        o.gui_options);
    fmt::print("gui: serving {}  (open it in a browser; Ctrl-C to stop)\n", gui->url());
    std::fflush(stdout);
  }

  std::unique_ptr<Recorder> recorder;
  if (!o.record.empty()) recorder = std::make_unique<Recorder>(o.record, 1.0 / dt, o.force);

  runtime::RunOptions run;
  // With the GUI the loop runs until Ctrl-C (or SIGTERM).
  // On the real-time clock --duration is wall seconds: a loop slower than its rate still ends on
  // time (a step count would run longer).
  run.steps = o.gui || o.realtime ? 0 : static_cast<int64_t>(std::ceil(o.duration / dt - 1e-9));
  if (o.realtime && !o.gui) run.seconds = o.duration;
  run.live = o.gui;  // paced by the page: detection on its own thread, frames pipelined
  g_stop = false;
  run.stop = &g_stop;
  run.on_error = [&](const runtime::StepError& error) {
    fmt::print(stderr, "saccade: error: {}\n", error.ToString());
  };
  // While a step waits for its frames, the GUI takes the commands that came meanwhile.
  if (gui) run.while_waiting = [&] { gui->WhileWaiting(); };
  run.step_timing = [&](const runtime::StepContext&, const runtime::StepTiming& timing) {
    latency.Add(timing);
  };
  run.after_step = [&](const runtime::StepContext& context) {
    const double t = context.time;
    figures.AfterStep(t, latest);
    const components::FixationScorer::Step scored = scorer.Update(context.step, t, latest);
    const bool fixated_now = scored.fixated_now;
    const std::string& status = scored.status;
    const std::vector<components::Fixation>& fixations = scorer.fixations();

    if (fixated_now && !o.json) {
      fmt::print("{}", components::FixationText(fixations.back(), t));
      std::fflush(stdout);
    }
    if (recorder) {
      const cv::Mat frame = gui::Compose(latest, t, status);
      recorder->Write(context.step, frame);
      if (fixated_now) {
        recorder->WriteFixation(static_cast<int>(fixations.size()), fixations.back().object, frame);
      }
    }
    // Done once every face has been fixated and let go.
    if (gui) {
      gui->AfterStep(context, latest, g_stop);
    } else if (faces_total > 0 && scorer.faces_done() == faces_total) {
      g_stop = true;
    }
  };

  auto previous_int = std::signal(SIGINT, OnDemoInterrupt);
  auto previous_term = std::signal(SIGTERM, OnDemoInterrupt);
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, run);
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);

  // Nothing ran (a device that would not open, a component that failed to start): the
  // error, printed above, is the whole story for people (the JSON and summary.json keep it).
  const bool nothing_ran = summary.steps == 0 && !summary.errors.empty();

  // ---- the report ----
  components::DemoReport report;
  report.pipeline = o.pipeline;
  report.scene = o.scene;
  report.hardware_file = spec.hardware_file;
  report.dt = dt;
  report.summary = summary;
  report.scorer = &scorer;
  report.truth = truth;
  report.capture_to_command_ms = latency.milliseconds();
  report.detection_age_ms = figures.detection_age_ms();
  report.exposure_samples = figures.exposure_samples();
  report.pair_counts = cameras->pair_counts();
  if (report.pair_counts) report.cameras_description = cameras->Describe();
  report.head = head_status;
  report.interrupted = g_stop.load() && scorer.faces_fixated() < faces_total;
  report.realtime = o.realtime;
  json report_json = report.Json();
  if (recorder) {
    report_json["record"] = {{"folder", o.record},
                             {"frames", recorder->frames()},
                             {"video", (fs::path(o.record) / "demo.avi").string()}};
    recorder->WriteSummary(report_json);
    recorder.reset();  // closes the video
  }
  if (o.json) {
    fmt::print("{}\n", report_json.dump(2));
  } else if (!nothing_ran) {
    fmt::print("{}", report.Text(o.record));
  }
  if (gui) fmt::print("{}\n", gui->Describe());
  if (!summary.errors.empty() && summary.stopped_on_error) return 1;
  if (scorer.faces_fixated() == 0 && !o.gui) {
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
  gui->add_option("--scene", o->scene, "Scene YAML (default: the demo's, scenes/portraits.yaml)")
      ->check(CLI::ExistingFile);
  gui->add_option("--pipeline", o->pipeline, "Pipeline YAML (default: the demo's)")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  auto* pipeline_option = gui->get_option("--pipeline");
  gui->add_option("--hardware", o->hardware,
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
      o->pipeline = ShippedFile("pipelines/remote.yaml");
    }
    return RunDemo(*o);
  };
}

Runner AddDemoCommand(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* demo = app.add_subcommand(
      "demo",
      "The main job, the active-vision loop of the seed paper, headless: the POPEYE head finds "
      "the faces on the scene's portraits (rejecting the cat), tracks each with CamShift, "
      "triangulates it and fixates it, closest first, moving on once inhibition of return "
      "suppresses it. Prints each fixation's object, 3D error against the true face centre, "
      "each eye's angular error as it began and the time it took; at the end each eye's "
      "largest error over each fixation, then the latency of every stage. "
      "Exit status: 0 when at least one face was fixated, 3 when none was, 1 on an error.");
  demo->add_option("--pipeline", o->pipeline, "Pipeline YAML (components and connections)")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  demo->add_option("--scene", o->scene,
                   "Scene YAML; replaces every component's `scene` parameter (default: the "
                   "pipeline's, scenes/portraits.yaml; scenes/portraits_moving.yaml shows "
                   "smooth pursuit)")
      ->check(CLI::ExistingFile);
  demo->add_option("--hardware", o->hardware,
                   "Hardware file: which robot runs the loop, replacing the pipeline's "
                   "`hardware:` line (pipelines/hardware/: simulator.yaml, "
                   "recorded_cameras.yaml, emulated_servos.yaml, mirror.yaml, robot.yaml)")
      ->check(CLI::ExistingFile);
  demo->add_option("--duration", o->duration,
                   "Longest run, in seconds of the loop's clock (simulated; wall seconds with "
                   "--realtime); it ends sooner once every face was fixated")
      ->capture_default_str();
  demo->add_option("--record", o->record,
                   "Folder for the annotated frames (frames/*.jpg), a video (demo.avi, MJPEG), "
                   "a PNG per fixation and summary.json");
  demo->add_flag("--force", o->force, "Replace an earlier recording in the --record folder");
  demo->add_flag("--json", o->json, "Print the report as JSON (the same as summary.json)");
  demo->add_flag("--realtime", o->realtime,
                 "Run on the wall clock at the pipeline's rate instead of simulated time");
  demo->add_flag("--keep-going", o->keep_going,
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
