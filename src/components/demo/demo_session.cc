#include "saccade/components/demo/demo_session.h"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <utility>

#include "saccade/components/demo/fixation_scoring.h"
#include "saccade/components/demo/recording.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/components/roles.h"
#include "saccade/core/error.h"

namespace saccade::components::demo {
namespace {

const DemoOptions& Checked(const DemoOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
  return options;
}

/// The pipeline file with the options' scene, transport entries, error policy and clock.
runtime::PipelineSpec LoadSpec(const DemoOptions& o) {
  runtime::PipelineSpec spec = runtime::LoadPipelineFile(o.pipeline, o.hardware);
  if (!o.scene.empty()) runtime::ReplaceScene(spec, o.scene, "--scene");
  spec.transport.update(o.transport);
  if (o.keep_going) spec.on_error = runtime::OnError::kContinue;
  if (o.realtime) {
    spec.clock.mode = runtime::ClockMode::kRealtime;
    spec.clock.rate_hz = 1.0 / spec.clock.step;
  }
  return spec;
}

}  // namespace

bool DemoOptions::IsValid(std::string* error) const {
  if (!(duration > 0.0) || !std::isfinite(duration)) {
    if (error != nullptr) *error = fmt::format("demo: --duration must be > 0 s, got {}", duration);
    return false;
  }
  return true;
}

struct DemoSession::Impl {
  Impl(const DemoOptions& o, Progress p);
  void Say(const std::string& line) const {
    if (progress) progress(line);
  }
  void AfterStep(const runtime::StepContext& context, Recorder* recorder, const RunHooks& hooks,
                 std::atomic<bool>& stop);
  DemoSummary Summarise(const runtime::RunSummary& run, bool stopped) const;

  DemoOptions options;
  Progress progress;
  runtime::PipelineSpec spec;
  runtime::Pipeline pipeline;
  // The robot by its roles (components/roles.h). Simulated cameras give ground truth; real
  // ones (hw.cameras) give none.
  std::string cameras_name;
  const EyeCamerasRole* cameras = nullptr;
  bool truth = false;
  std::optional<CaptureToCommand> latency;
  LoopFigures figures;
  std::optional<FixationScorer> scorer;
  Latest latest;
  std::optional<HeadStatusMessage> head_status;
  bool ran = false;
};

DemoSession::Impl::Impl(const DemoOptions& o, Progress p)
    : options(Checked(o)),
      progress(std::move(p)),
      spec(LoadSpec(options)),
      pipeline(options.head.empty()
                   ? runtime::Pipeline::Build(spec)
                   : runtime::Pipeline::Build(spec, RegistryWithHead(options.head, "--head"))),
      figures(pipeline) {
  cameras = pipeline.FindRole<EyeCamerasRole>(&cameras_name);
  if (cameras == nullptr) {
    throw InvalidArgument(
        "demo: pipeline " + options.pipeline +
        " has no eye cameras (a sim.cameras, hw.cameras or remote.cameras component)");
  }
  std::string head_name;
  pipeline.FindRole<HeadRole>(&head_name);
  latency.emplace(spec, cameras_name, head_name);
  truth = cameras->rendered() != nullptr;
  // Real cameras: the scene only carries the robot; its pictures are not what they see.
  scorer.emplace(cameras->scene(), truth);
  if (!truth) {
    for (const runtime::ComponentSpec& c : spec.components) {
      if (c.name != cameras_name) continue;
      Say(fmt::format(
          "real cameras ({}): no ground truth; fixations are reported as triangulated\n", c.type));
    }
  }
  TapLoopOutputs(pipeline, &latest);
  Tap<HeadStatusMessage>(pipeline, [this](const HeadStatusMessage& m) {
    if (m.fault != (head_status ? head_status->fault : "") && !m.fault.empty()) {
      Say(fmt::format("t = {:6.2f} s  head FAULT: {}\n", m.time, m.fault));
    }
    head_status = m;
  });
}

void DemoSession::Impl::AfterStep(const runtime::StepContext& context, Recorder* recorder,
                                  const RunHooks& hooks, std::atomic<bool>& stop) {
  const double t = context.time;
  figures.AfterStep(t, latest);
  const FixationScorer::Step scored = scorer->Update(context.step, t, latest);
  const std::vector<Fixation>& fixations = scorer->fixations();
  if (scored.fixated_now) Say(FixationText(fixations.back(), t));
  if (recorder != nullptr) {
    const cv::Mat frame = Compose(latest, t, scored.status);
    recorder->Write(context.step, frame);
    if (scored.fixated_now) {
      recorder->WriteFixation(static_cast<int>(fixations.size()), fixations.back().object, frame);
    }
  }
  if (hooks.after_step) hooks.after_step(context, latest, stop);
  // Done once every face has been fixated and let go; a live front end decides for itself.
  const int faces = scorer->faces_total();
  if (!options.live && faces > 0 && scorer->faces_done() == faces) stop = true;
}

DemoSummary DemoSession::Impl::Summarise(const runtime::RunSummary& run, bool stopped) const {
  DemoSummary out;
  out.pipeline = options.pipeline;
  out.scene = options.scene;
  out.hardware_file = spec.hardware_file;
  out.dt = spec.clock.step;
  out.run = run;
  out.fixations = scorer->fixations();
  out.faces_total = scorer->faces_total();
  out.faces_fixated = scorer->faces_fixated();
  out.decoys = scorer->DecoysJson();
  out.truth = truth;
  out.capture_to_command_ms = latency->milliseconds();
  out.detection_age_ms = figures.detection_age_ms();
  out.exposure_samples = figures.exposure_samples();
  out.pair_counts = cameras->pair_counts();
  if (out.pair_counts) out.cameras_description = cameras->Describe();
  out.head = head_status;
  out.interrupted = stopped && out.faces_fixated < out.faces_total;
  out.realtime = options.realtime;
  out.record = options.record;
  return out;
}

DemoSession::DemoSession(const DemoOptions& options, Progress progress)
    : impl_(std::make_unique<Impl>(options, std::move(progress))) {}

DemoSession::~DemoSession() = default;

runtime::Pipeline& DemoSession::pipeline() { return impl_->pipeline; }

const scene::Scene& DemoSession::scene() const { return impl_->cameras->scene(); }

DemoSummary DemoSession::Run(std::atomic<bool>& stop, const RunHooks& hooks) {
  Impl& s = *impl_;
  SACCADE_ASSERT(!s.ran, "DemoSession::Run: a session runs once");
  s.ran = true;
  const DemoOptions& o = s.options;
  const double dt = s.spec.clock.step;
  std::unique_ptr<Recorder> recorder;
  if (!o.record.empty()) recorder = std::make_unique<Recorder>(o.record, 1.0 / dt, o.force);

  runtime::RunOptions run;
  // Live, the loop runs until stopped. On the real-time clock the duration is wall seconds: a
  // loop slower than its rate still ends on time (a step count would run longer).
  run.steps = o.live || o.realtime ? 0 : static_cast<int64_t>(std::ceil(o.duration / dt - 1e-9));
  if (o.realtime && !o.live) run.seconds = o.duration;
  run.live = o.live;  // paced by the front end: detection on its own thread, frames pipelined
  run.stop = &stop;
  run.on_error = hooks.on_error;
  // While a step waits for its frames, the front end takes the commands that came meanwhile.
  run.while_waiting = hooks.while_waiting;
  run.step_timing = [&s](const runtime::StepContext&, const runtime::StepTiming& timing) {
    s.latency->Add(timing);
  };
  run.after_step = [&](const runtime::StepContext& context) {
    s.AfterStep(context, recorder.get(), hooks, stop);
  };
  const runtime::RunSummary ran = runtime::RunPipeline(s.pipeline, run);
  DemoSummary summary = s.Summarise(ran, stop.load());
  if (recorder) {
    summary.recorded_frames = recorder->frames();
    recorder->WriteSummary(summary.Json());
  }
  return summary;  // the recorder closes the video
}

}  // namespace saccade::components::demo
