#pragma once
// The summary of `saccade demo`: what the loop fixated, against the scene's ground truth, and
// how fast it ran (steps per second, the real-time factor, the latency of every stage and
// from capture to motor command). JSON for scripts and summary.json (docs/demo.md), text
// for people.
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/demo/fixation_scoring.h"
#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/core/streaming_stats.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"

namespace saccade::components::demo {

/// The loop's latency, per step: from the end of the eye cameras' capture (its images
/// delivered) to the end of the component that commands the head (the source of the head's
/// `command` input), wall clock: every stage in between, run one after the other or at the
/// same time, and the loop's own time.
class CaptureToCommand {
 public:
  /// `cameras` and `head`: the components that play those roles (Pipeline::FindRole).
  CaptureToCommand(const runtime::PipelineSpec& spec, const std::string& cameras,
                   const std::string& head);
  /// RunOptions::step_timing's figures.
  void Add(const runtime::StepTiming& timing);
  const StreamingStats& milliseconds() const { return ms_; }

 private:
  std::optional<std::size_t> cameras_index_, commander_index_;
  StreamingStats ms_;  // constant memory however long the run
};

/// Figures of the loop gathered step by step: how old the faces were when the loop received
/// them (from their image's capture to the step that brought them: 0 for detection within
/// the step, more with vision.face_detector's latency_steps; milliseconds of the loop's
/// clock), and how many motion-blur sub-frames each camera frame took.
class LoopFigures {
 public:
  /// Taps every faces output of `pipeline`, which must not outlive this.
  explicit LoopFigures(runtime::Pipeline& pipeline);
  LoopFigures(const LoopFigures&) = delete;
  LoopFigures& operator=(const LoopFigures&) = delete;
  /// After each step, at its time, with what the loop said in it.
  void AfterStep(double time, const Latest& latest);
  const StreamingStats& detection_age_ms() const { return age_ms_; }
  /// Frames by the number of sub-frames their exposure was drawn in.
  const std::map<int, int64_t>& exposure_samples() const { return exposure_samples_; }

 private:
  std::vector<double> captured_;  // this step's faces: their images' times
  StreamingStats age_ms_;
  std::map<int, int64_t> exposure_samples_;
  std::map<std::string, int64_t> last_frame_;  // per camera, the frame counted last
};

/// What a demo run did (DemoSession::Run): every fixation against the scene's ground truth, the
/// decoys, the speed and latency of the loop, the head's last status and the recording.
struct DemoSummary {
  std::string pipeline;             ///< the pipeline file
  std::string scene;                ///< --scene; empty: the pipeline's
  std::string hardware_file;        ///< empty: the pipeline's robot (simulated)
  double dt = 0.0;                  ///< s, the clock's step
  runtime::RunSummary run;          ///< the scheduler's: steps, errors, every stage's timing
  std::vector<Fixation> fixations;  ///< in the order attention selected them
  int faces_total = 0;              ///< faces in the scene's pictures (0 without ground truth)
  int faces_fixated = 0;            ///< different faces fixated
  nlohmann::json decoys = nlohmann::json::array();  ///< FixationScorer::DecoysJson
  bool truth = false;                       ///< rendered cameras: fixations scored against truth
  StreamingStats capture_to_command_ms;     ///< per step, from the cameras to the head command
  StreamingStats detection_age_ms;          ///< LoopFigures
  std::map<int, int64_t> exposure_samples;  ///< LoopFigures
  std::optional<CameraPairCounts> pair_counts;  ///< real cameras
  std::string cameras_description;              ///< real cameras: a line about the sources
  std::optional<HeadStatusMessage> head;        ///< the head's last status
  bool interrupted = false;                     ///< stopped before every face was fixated
  bool realtime = false;                        ///< on the real-time clock (overruns count)
  std::string record;           ///< the recording's folder (recording.h); empty: none
  int64_t recorded_frames = 0;  ///< frames written to it

  double sim_time() const { return run.sim_time + dt; }
  double steps_per_second() const;
  /// Simulated seconds per wall second: 1 is as fast as the cameras deliver.
  double real_time_factor() const;
  /// Nothing ran (a device that would not open, a component that failed to start): the
  /// errors are the whole story.
  bool nothing_ran() const { return run.steps == 0 && !run.errors.empty(); }

  /// Its JSON form: `saccade demo --json` and the recording's summary.json (docs/demo.md).
  nlohmann::json Json() const;
  /// One line: the faces fixated, in how much of the loop's time, steps and wall time.
  std::string BriefReport() const;
  /// The report after the run: the brief line, speed, each fixation's error over its dwell,
  /// the cameras, the head, the decoys, the latency of every stage and the recording.
  std::string FullReport() const;
};

/// The line printed when a fixation arrives at time `t`.
std::string FixationText(const Fixation& f, double t);

}  // namespace saccade::components::demo
