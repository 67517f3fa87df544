#pragma once
// Runs a pipeline: Start every component, Step them in order each tick, Stop them. One step is
// written once, in Stepper (below): RunPipeline loops over it, adding the pacing, the run's
// bounds and its callbacks; Python's Pipeline.step calls it too (docs/python.md).
//
// Each step runs in levels: a component's level is one past the highest of those it reads
// without a delay, so the components of one level do not depend on each other in the step
// (the two eyes' detectors). With more than one thread (PipelineSpec::threads) a level's
// components run at the same time; what they emit is held back and delivered after the level,
// in execution order (port.h's DeferredEmits), so the run is the same, bit for bit, as the
// serial one. A thread-affine component (Component::thread_affine) runs on the calling thread.
//
// Simulated clock: time = step * clock.step, no waiting; the same pipeline and seed give
// the same run, bit for bit. With `clock.source` (pipeline.h) a step's time is instead the
// stamp of the message the source's topic reader takes for it, waiting as that input's options
// say: the receiving half of a split pipeline steps on the sender's capture times.
// Real time: one tick every 1 / rate_hz seconds of wall clock (the loop sleeps until the next
// tick; a tick that ends after the next one was due is an overrun, counted, and the missed
// ticks are skipped rather than bunched).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/runtime/pipeline.h"

namespace saccade::runtime {

/// A component's failure during a run.
struct StepError {
  std::string component;
  std::string phase;  ///< "start", "step" or "stop"
  int64_t step = -1;  ///< the step index ("step" phase), -1 otherwise
  std::string message;
  /// "component 'detector' failed at step 12: <message>"
  std::string ToString() const;
};

/// Step times of one component over a run, in milliseconds.
struct ComponentTiming {
  std::string name;
  int64_t steps = 0;  ///< steps timed
  double mean_ms = 0.0;
  double median_ms = 0.0;
  double p95_ms = 0.0;
  double max_ms = 0.0;
  int64_t errors = 0;
};

/// What a run did and where its time went.
struct RunSummary {
  int64_t steps = 0;              ///< steps completed (the failing step included)
  double sim_time = 0.0;          ///< s: context time of the last step
  double wall_seconds = 0.0;      ///< from Start to the end of Stop
  bool stopped_on_error = false;  ///< on_error: stop ended the run
  /// The first kMaxKeptErrors failures, in order (every one goes to RunOptions::on_error);
  /// errors_total counts them all, so a run that fails at every step keeps constant memory.
  std::vector<StepError> errors;
  int64_t errors_total = 0;
  static constexpr std::size_t kMaxKeptErrors = 100;
  std::vector<ComponentTiming> components;  ///< in execution order
  /// Per step, the loop's time outside components' own work: message delivery, the
  /// scheduler's bookkeeping (not the real-time sleep). Mean, median and p95 in ms.
  double overhead_mean_ms = 0.0;
  double overhead_median_ms = 0.0;
  double overhead_p95_ms = 0.0;
  /// overhead / (overhead + components' time), over the whole run, in [0, 1].
  double overhead_share = 0.0;
  int64_t overruns = 0;  ///< real time: ticks that ended after the next was due

  /// One line: steps, errors, overhead share.
  std::string BriefReport() const;
  /// A table: one line per component plus the overhead.
  std::string FullReport() const;
};

/// One step's timing, per component in execution order (seconds).
struct StepTiming {
  /// Each component's own time in the step (0: disabled, or not stepped after an error).
  std::vector<double> own;
  /// When each finished, its messages delivered, from the step's start (0: not stepped). With
  /// parallel levels, the end-to-end latency between two components is the difference.
  std::vector<double> finished;
  /// The loop's time outside the components' own work: the step's wall time less, per level,
  /// the longest own time in it (its sum when the level ran one after the other): delivery,
  /// scheduling.
  double overhead = 0.0;
};

struct RunOptions {
  /// Overrides the pipeline's clock.steps when >= 0 (0: until `stop`).
  int64_t steps = -1;
  /// When > 0, also ends the run before the first step whose time reaches it (seconds of the
  /// run's clock: on the real-time clock the wall seconds since the loop began, so a loop slower
  /// than its rate still ends on time; steps then bounds nothing and may be 0).
  double seconds = 0.0;
  /// The loop runs live, paced against the wall clock from outside (the GUI's after_step
  /// waits): components see StepContext::realtime true -- work may finish when it does, as on
  /// the real-time clock -- while the time stays the simulated clock's (step * dt).
  bool live = false;
  /// Set (from another thread, a signal handler) to end the run after the current step.
  const std::atomic<bool>* stop = nullptr;
  /// Told of each failure as it happens (e.g. to log it); may be empty.
  std::function<void(const StepError&)> on_error;
  /// Called after each step with its context (progress, recording); may be empty.
  std::function<void(const StepContext&)> after_step;
  /// Called after each step (before after_step) with its timing (StepTiming). For per-step
  /// latencies; may be empty.
  std::function<void(const StepContext&, const StepTiming&)> step_timing;
  /// Called while a component waits on a device within a step (StepContext::while_waiting),
  /// every few milliseconds, on the loop's thread and only while no other component runs:
  /// e.g. a GUI applying the commands that arrived. May be empty.
  std::function<void()> while_waiting;
};

/// The time of simulated step `step`: step * clock.step; with a time source
/// (Pipeline::time_source), the stamp of the message it takes for the step (k * clock.step
/// exactly when the stamp is within a nanosecond of it: stamps cross in whole ns), or, when none
/// came, `previous` (the last step's time) + clock.step: a sender gone quiet never stops the clock.
/// A sender that restarted starts its stamps, and so the time, again.
double SimulatedStepTime(const Pipeline& pipeline, int64_t step, double previous);

/// How a Stepper steps. RunPipeline fills it from its RunOptions; Python's Pipeline.step sets
/// simulated_time.
struct StepperOptions {
  /// The simulated clock's times (SimulatedStepTime: step * clock.step, or clock.source's
  /// stamps) on either clock, for a caller that paces the steps itself (Python's
  /// Pipeline.step). When false, a real-time pipeline's step time is the wall seconds since
  /// Start, and its components see StepContext::realtime true.
  bool simulated_time = false;
  /// Components see StepContext::realtime true on simulated times (RunOptions::live).
  bool live = false;
  /// Told of each failure (start, step, stop) as it happens; may be empty.
  std::function<void(const StepError&)> on_error;
  /// Offered to a component that waits on a device (RunOptions::while_waiting); may be empty.
  std::function<void()> while_waiting;
};

/// What one step did (Stepper::Step).
struct StepResult {
  /// The step's context: index, time, dt, realtime (the pipeline's, without a component's seed
  /// or while_waiting), as RunOptions::after_step gets it.
  StepContext context;
  StepTiming timing;
  /// The components that failed in the step, in execution order (also in the summary and told
  /// to StepperOptions::on_error).
  std::vector<StepError> errors;
  /// A component failed and the pipeline's on_error is stop: the step ended early (below) and
  /// the run should end.
  bool stopped_on_error = false;
};

/// Runs a pipeline one step at a time: the step that RunPipeline loops over and that Python's
/// Pipeline.step calls. Start once, then Step any number of times, then Stop (the destructor
/// stops what is still started, its failures dropped).
///
/// One step:
///   1. Its context (Next): step = the steps done before it; time = SimulatedStepTime on the
///      simulated clock (taking clock.source's message, whose wait counts as the source
///      reader's own time) or, on the real-time clock, the wall seconds since Start; dt =
///      clock.step (1 / rate_hz in real time); realtime as StepperOptions says.
///   2. Pipeline::DeliverDelayed, then Pipeline::BeginStep.
///   3. The components level by level (the file comment): each enabled one Steps with its own
///      seed; a level of several runs at the same time on the pipeline's threads, what they emit
///      delivered after the level in execution order, a thread-affine one on the calling
///      thread; StepperOptions::while_waiting is offered only where nothing else runs. After a
///      component's step its inputs are marked seen; a disabled one is not stepped, and its
///      inputs are marked seen all the same.
///   4. A component's exception is caught, not thrown: it is told to on_error, kept in the
///      summary and returned in StepResult::errors. With on_error: stop the step ends there:
///      one after the other, the components after the failing one are not stepped; in a
///      parallel level, the level's others finish and the later levels are skipped. With
///      on_error: continue the step goes on.
///   5. Pipeline::EndStep, a failed step included.
///
/// The pipeline must outlive the stepper. Not thread-safe: one thread calls it, and the
/// thread-affine components run on that thread.
class Stepper {
 public:
  explicit Stepper(Pipeline& pipeline, StepperOptions options = {});
  ~Stepper();
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  /// Starts every component in execution order (and the pipeline's threads). Returns the first
  /// failure ("start" phase; also told to on_error and kept in the summary), after which no
  /// step may run and Stop stops those that started; std::nullopt when all started. Throws
  /// InvalidArgument when called twice.
  std::optional<StepError> Start();
  /// The next step's context (1. above), prepared once: later calls return it again until Step
  /// runs it. For a caller that looks at the time before the step (RunOptions::seconds). Throws
  /// InvalidArgument unless started without failure and not stopped.
  const StepContext& Next();
  /// Runs the next step (Next's context, prepared now if Next was not called) and returns what
  /// it did; valid until the next call. Never throws for a component's failure; throws
  /// InvalidArgument unless started without failure and not stopped.
  const StepResult& Step();
  /// Stops every started component, the last started first; returns their failures ("stop"
  /// phase; also told to on_error and kept in the summary). Only the first call stops.
  std::vector<StepError> Stop();

  /// Steps run so far.
  int64_t steps_done() const;
  /// What the stepper did so far, as RunPipeline reports it: steps, sim_time, stopped_on_error,
  /// errors, the components' timings and the overhead; wall_seconds from Start to the end of
  /// Stop (or to now, before Stop); overruns 0 (pacing is RunPipeline's).
  RunSummary Summary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Runs `pipeline` once: a Stepper's Start, its steps until the run's bound (RunOptions::steps,
/// seconds, stop, or a failure with on_error: stop), paced on the real-time clock, and Stop.
/// Component failures are reported in the summary, not thrown; throws InvalidArgument when
/// neither steps nor a stop flag bound the run.
RunSummary RunPipeline(Pipeline& pipeline, const RunOptions& options = {});

}  // namespace saccade::runtime
