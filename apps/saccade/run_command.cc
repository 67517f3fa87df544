// run: any pipeline file, headless, until its clock's steps are done or Ctrl-C. Topic
// connections go over DDS (docs/dds.md), so that one pipeline split in two files runs as two
// processes: `saccade run pipelines/robot.yaml` and `saccade run pipelines/perception.yaml`.

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/components/demo/fixation_scoring.h"
#include "saccade/components/demo/loop_outputs.h"
#include "saccade/components/demo/summary.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/dds/transport.h"
#include "saccade/record/player.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "saccade/scene/scene.h"

namespace saccade::app {
namespace {

using nlohmann::json;

std::atomic<bool> g_run_stop{false};
extern "C" void OnRunInterrupt(int) { g_run_stop = true; }

struct RunCommandOptions {
  std::string pipeline;
  std::string hardware;
  std::string scene;
  std::string head;
  int64_t steps = -1;
  bool realtime = false;
  bool json = false;
  bool score = false;
  std::string joints_csv;
  McapOptions record;
  std::string play;  // --play FILE.mcap
  record::PlayOptions play_options;
  DdsOverrides dds;  // the pipeline's `transport:` map, overridden
};

/// The head's state as the pipeline's components emit it, to --joints-csv (when given) and as
/// fixations: a fixation is the head coming to rest after a move (JointStateMessage::arrived
/// turning true). `csv` and `fixations` must outlive the pipeline's run.
void LogJoints(runtime::Pipeline& pipeline, const RunCommandOptions& o, std::ofstream* csv,
               json* fixations) {
  auto was_arrived = std::make_shared<bool>(true);
  auto header_written = std::make_shared<bool>(false);
  components::demo::Tap<components::JointStateMessage>(
      pipeline, [=, &o](const components::JointStateMessage& m) {
        const head::JointState& q = m.positions;
        if (csv) {
          // time, one column per joint (the head's names: POPEYE's pan,tilt,left,right), arrived.
          if (!*header_written) {
            *csv << "time";
            for (const std::string& name : q.names()) *csv << "," << name;
            *csv << ",arrived\n";
            *header_written = true;
          }
          *csv << fmt::format("{:.6f}", m.time);
          for (int i = 0; i < q.size(); ++i) *csv << fmt::format(",{:.17g}", q[i]);
          *csv << fmt::format(",{}\n", m.arrived ? 1 : 0);
        }
        if (m.arrived && !*was_arrived) {
          json fixation = {{"time", m.time}};
          std::string text;
          for (int i = 0; i < q.size(); ++i) {
            fixation[q.name(i)] = q[i];
            text += fmt::format(" {} {:+.4f}", q.name(i), q[i]);
          }
          fixations->push_back(fixation);
          if (!o.json) {
            fmt::print("t = {:6.2f} s  fixation:{} rad\n", m.time, text);
            std::fflush(stdout);
          }
        }
        *was_arrived = m.arrived;
      });
}

/// --score: the fixations attention selected, against the scene's ground truth, as `saccade
/// demo` scores them, from what this process sees (its images, selection, target, joints):
/// perception.yaml's half of a simulated robot scores the split loop. Taps the loop's outputs
/// into `latest`.
std::unique_ptr<components::demo::FixationScorer> MakeScorer(runtime::Pipeline& pipeline,
                                                             const RunCommandOptions& o,
                                                             components::demo::Latest* latest) {
  std::shared_ptr<const scene::Scene> scene = pipeline.resources().Default<scene::Scene>("scene");
  if (!scene) {
    throw InvalidArgument("run: --score needs the pipeline's scene (`scene:` in " + o.pipeline +
                          "): the ground truth comes from it");
  }
  bool selects = false;
  for (const auto& component : pipeline.components()) {
    for (const auto& output : component->outputs()) {
      selects =
          selects || output->message_type() == runtime::MessageName<components::SelectionMessage>();
    }
  }
  if (!selects) {
    throw InvalidArgument("run: --score: " + o.pipeline +
                          " selects no targets (no vision.attention): there are no fixations "
                          "to score in this process");
  }
  auto scorer = std::make_unique<components::demo::FixationScorer>(*scene, /*truth=*/true);
  if (scorer->faces_total() == 0) {
    throw InvalidArgument("run: --score: the scene has no pictures of faces to score against");
  }
  components::demo::TapLoopOutputs(pipeline, latest);
  return scorer;
}

/// The result: JSON, or the scored faces and the run's brief report.
void PrintResult(const RunCommandOptions& o, const runtime::RunSummary& summary,
                 const json& fixations, const components::demo::FixationScorer* scorer) {
  if (o.json) {
    json out = {{"pipeline", o.pipeline},
                {"steps", summary.steps},
                {"errors", summary.errors_total},
                {"fixations", fixations}};
    if (scorer) {
      json scored = json::array();
      for (const components::demo::Fixation& f : scorer->fixations()) {
        scored.push_back(components::demo::FixationJson(f));
      }
      out["faces"] = scorer->faces_total();
      out["faces_fixated"] = scorer->faces_fixated();
      out["scored"] = scored;
    }
    fmt::print("{}\n", out.dump(2));
    return;
  }
  if (scorer) {
    fmt::print("{} of {} faces fixated\n", scorer->faces_fixated(), scorer->faces_total());
  }
  fmt::print("{}: {}\n", o.pipeline, summary.BriefReport());
}

int Run(const RunCommandOptions& o) {
  components::RegisterComponents();
  dds::RegisterDdsTransport(runtime::ComponentRegistry::Global());
  runtime::PipelineSpec spec = runtime::LoadPipelineFile(o.pipeline, o.hardware);
  if (!o.scene.empty()) runtime::ReplaceScene(spec, o.scene, "--scene");
  if (o.realtime) {
    spec.clock.rate_hz = 1.0 / spec.clock.step;
    spec.clock.mode = runtime::ClockMode::kRealtime;
    spec.clock.source.clear();  // the wall clock times the steps, not the sender's stamps
  }
  ApplyDdsOverrides(o.dds, spec);
  runtime::Pipeline pipeline =
      o.head.empty()
          ? runtime::Pipeline::Build(spec)
          : runtime::Pipeline::Build(spec, components::RegistryWithHead(o.head, "--head"));

  std::unique_ptr<std::ofstream> csv;
  if (!o.joints_csv.empty()) {
    csv = std::make_unique<std::ofstream>(o.joints_csv);
    if (!*csv) throw InvalidArgument("run: cannot write --joints-csv " + o.joints_csv);
    // The header comes with the first joint state, which names the head's joints.
  }
  json fixations = json::array();
  LogJoints(pipeline, o, csv.get(), &fixations);
  components::demo::Latest latest;
  std::unique_ptr<components::demo::FixationScorer> scorer;
  if (o.score) scorer = MakeScorer(pipeline, o, &latest);

  std::unique_ptr<Recording> recording;
  if (!o.record.path.empty()) {
    recording = std::make_unique<Recording>(
        o.record, pipeline, RunMetadata("run", o.pipeline, o.scene, o.head, o.hardware));
  }
  std::unique_ptr<record::McapPlayer> player;
  if (!o.play.empty()) {
    player = std::make_unique<record::McapPlayer>(o.play, spec.transport, o.play_options);
    for (const std::string& skipped : player->skipped()) {
      log::Info("play: not played: {}", skipped);
    }
  }
  runtime::RunOptions run;
  run.steps = o.steps;
  const double dt = spec.clock.step;
  run.after_step = [&](const runtime::StepContext& context) {
    if (recording) recording->AfterStep(context);
    // The recording played to its end: the pipeline stepped on its last step's stamps.
    if (player && context.time >= player->last_time() - 1e-6) g_run_stop = true;
    if (!scorer) return;
    // The frame index of the step's images (the sender's, with clock.source).
    const auto frame = static_cast<int64_t>(std::llround(context.time / dt));
    if (scorer->Update(frame, context.time, latest).fixated_now && !o.json) {
      fmt::print("{}", components::demo::FixationText(scorer->fixations().back(), context.time));
      std::fflush(stdout);
    }
  };
  g_run_stop = false;
  run.stop = &g_run_stop;
  run.on_error = [&](const runtime::StepError& error) {
    fmt::print(stderr, "saccade: error: {}\n", error.ToString());
  };
  if (o.steps < 0 && spec.clock.steps == 0) run.steps = 0;  // until Ctrl-C
  auto previous_int = std::signal(SIGINT, OnRunInterrupt);
  auto previous_term = std::signal(SIGTERM, OnRunInterrupt);
  if (player) player->Start();
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, run);
  if (player) {
    const record::PlayStats played = player->Stop();
    if (!o.json) {
      fmt::print("play: {} steps, {} messages of {}{}\n", played.steps, played.messages, o.play,
                 played.late > 0 ? fmt::format(", {} answered late", played.late) : "");
    }
  }
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  if (csv) csv->flush();
  if (recording) {
    const std::string line = recording->Close();
    if (!o.json) fmt::print("{}", line);
  }
  PrintResult(o, summary, fixations, scorer.get());
  // Stops the components (the DDS readers report what crossed) before exiting.
  return !summary.errors.empty() && summary.stopped_on_error ? 1 : 0;
}

}  // namespace

Runner AddRunCommand(CLI::App& app) {
  auto o = std::make_shared<RunCommandOptions>();
  auto* run = app.add_subcommand(
      "run",
      "Run any pipeline file headless (runtime/pipeline.h). Connections that name a topic go "
      "over DDS on ROS 2's wire (docs/dds.md), so that one pipeline split in two files runs as "
      "two processes, on one machine or two: e.g. `saccade run pipelines/robot.yaml` and "
      "`saccade run pipelines/perception.yaml`, which step in lockstep on the simulated clock "
      "(the robot's head waits for perception's answer to each frame pair) and so move the "
      "head as pipelines/demo.yaml does in one process. Prints each fixation (the head coming "
      "to rest) and the run's summary; the DDS readers log what crossed (messages, lost, late, "
      "restarts).");
  run->add_option("pipeline", o->pipeline, "The pipeline file")->required();
  run->add_option("--hardware", o->hardware, "Hardware file replacing the pipeline's own");
  run->add_option("--scene", o->scene, "Scene replacing the pipeline's (and its hardware's)");
  run->add_option("--head", o->head,
                  "Head file (robots/*.yaml) in place of the scene's robot head, at its home "
                  "joints")
      ->check(CLI::ExistingFile);
  run->add_option("--steps", o->steps,
                  "Steps to run (default: the file's clock.steps; 0 until "
                  "Ctrl-C)");
  run->add_flag("--realtime", o->realtime,
                "Run at the wall clock's pace (rate 1 / clock.step); a clock.source and "
                "lockstep are then not used: the steps take the wall clock's time and the "
                "newest messages, and wait for no answer");
  run->add_flag("--json", o->json,
                "Print the result as JSON: steps, errors, fixations (and, with --score, the "
                "scored fixations)");
  run->add_flag("--score", o->score,
                "Score the fixations that attention selects against the ground truth of the "
                "pipeline's scene, as `saccade demo` does (3D error, eye axis errors), from what "
                "this process receives: for the perception half of a simulated robot");
  run->add_option("--joints-csv", o->joints_csv,
                  "Write every head state the pipeline emits (time, pan, tilt, left, right in "
                  "rad, arrived) to this CSV file");
  run->add_option("--record", o->record.path,
                  "Record every output of the run to this MCAP file (ROS 2 messages: images, "
                  "camera info, joint states and targets, TF; JSON: detections, tracks, "
                  "selections, ground truth), for Foxglove, rosbag2 and `saccade mcap`");
  run->add_flag("--force", o->record.force, "Replace an existing --record file");
  AddRecordTuning(run, o->record);
  run->add_option("--play", o->play,
                  "Play this MCAP recording (of `--record`, or rosbag2's of saccade's topics) "
                  "as the robot: its ROS 2 messages are published again on the pipeline's DDS "
                  "domain, so that a pipeline reading topics (pipelines/perception.yaml) runs on "
                  "it as on the live robot; the run ends with the recording")
      ->check(CLI::ExistingFile);
  run->add_option("--play-pace", o->play_options.pace,
                  "lockstep: each recorded step waits for the pipeline's answer (its lockstep "
                  "head/command output), so it computes what it did live, bit for bit; "
                  "recorded: the recorded rate (times --play-speed); fast: no waiting (frames "
                  "the pipeline is too slow for are skipped)")
      ->check(CLI::IsMember({"lockstep", "recorded", "fast"}))
      ->capture_default_str();
  run->add_option("--play-speed", o->play_options.speed,
                  "With --play-pace recorded: recorded seconds per wall second")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  AddDdsOptions(run, o->dds);
  return [o] { return Run(*o); };
}

}  // namespace saccade::app
