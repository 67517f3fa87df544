#include "saccade/runtime/scheduler.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <optional>
#include <thread>
#include <utility>

#include "runtime/internal_thread_pool.h"
#include "saccade/core/streaming_stats.h"
#include "saccade/runtime/port.h"

namespace saccade::runtime {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct Stats {
  double mean = 0.0;
  double median = 0.0;
  double p95 = 0.0;
  double max = 0.0;
};

// Milliseconds from seconds; median and p95 by nearest rank, within 1 % (streaming_stats.h).
Stats Summarise(const StreamingStats& seconds) {
  return {1e3 * seconds.mean(), 1e3 * seconds.Quantile(0.5), 1e3 * seconds.Quantile(0.95),
          1e3 * seconds.max()};
}

std::string What(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown exception";
  }
}

// The components in levels: a component's level is one past the highest level of the
// components it reads without a delay; each level in execution order.
std::vector<std::vector<std::size_t>> Levels(const Pipeline& pipeline) {
  const auto& components = pipeline.components();
  const PipelineSpec& spec = pipeline.spec();
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < components.size(); ++i) index[components[i]->name()] = i;
  std::vector<int> level(components.size(), 0);
  int deepest = 0;
  for (const ComponentSpec& c : spec.components) {
    const auto self = index.find(c.name);
    if (self == index.end()) continue;
    int l = 0;
    for (const ConnectionSpec& input : c.inputs) {
      const auto from = index.find(input.from_component);
      if (input.delay != 0 || from == index.end() || from->second >= self->second) continue;
      l = std::max(l, level[from->second] + 1);
    }
    level[self->second] = l;
    deepest = std::max(deepest, l);
  }
  std::vector<std::vector<std::size_t>> levels(static_cast<std::size_t>(deepest) + 1);
  for (std::size_t i = 0; i < components.size(); ++i) {
    levels[static_cast<std::size_t>(level[i])].push_back(i);
  }
  return levels;
}

}  // namespace

std::string StepError::ToString() const {
  if (phase == "step") {
    return fmt::format("component '{}' failed at step {}: {}", component, step, message);
  }
  return fmt::format("component '{}' failed in {}: {}", component, phase, message);
}

std::string RunSummary::BriefReport() const {
  return fmt::format("{} steps, {} errors{}, overhead {:.4f} ms/step ({:.2f}% of the loop){}",
                     steps, errors_total, stopped_on_error ? " (stopped on error)" : "",
                     overhead_mean_ms, 100.0 * overhead_share,
                     overruns > 0 ? fmt::format(", {} overruns", overruns) : "");
}

std::string RunSummary::FullReport() const {
  std::string text = BriefReport() + "\n";
  text += fmt::format("{:<24} {:>8} {:>10} {:>10} {:>10} {:>10} {:>7}\n", "component", "steps",
                      "mean ms", "median ms", "p95 ms", "max ms", "errors");
  for (const ComponentTiming& c : components) {
    text += fmt::format("{:<24} {:>8} {:>10.4f} {:>10.4f} {:>10.4f} {:>10.4f} {:>7}\n", c.name,
                        c.steps, c.mean_ms, c.median_ms, c.p95_ms, c.max_ms, c.errors);
  }
  text += fmt::format("{:<24} {:>8} {:>10.4f} {:>10.4f} {:>10.4f}\n", "(outside components)", steps,
                      overhead_mean_ms, overhead_median_ms, overhead_p95_ms);
  for (const StepError& error : errors) text += error.ToString() + "\n";
  return text;
}

double SimulatedStepTime(const Pipeline& pipeline, int64_t step, double previous) {
  const double dt = pipeline.spec().clock.step;
  // A product, not a running sum: no drift, the same on every run.
  if (pipeline.time_source() == nullptr) return static_cast<double>(step) * dt;
  const std::optional<double> stamp = pipeline.time_source()->NextTime();
  if (stamp) {
    // Stamps cross as whole nanoseconds: one within a nanosecond of the step grid is the
    // sender's simulated time, k * step, exactly (the same timers as in one process).
    const double k = std::round(*stamp / dt);
    return std::abs(*stamp - k * dt) <= 1e-9 ? k * dt : *stamp;
  }
  return step == 0 ? 0.0 : previous + dt;
}

// The stepper's state and its step, the serial and the parallel schedule alike (scheduler.h).
struct Stepper::Impl {
  Impl(Pipeline& p, StepperOptions o)
      : pipeline(p), options(std::move(o)), n(p.components().size()), levels(Levels(p)) {
    const PipelineSpec& spec = pipeline.spec();
    realtime_clock = spec.clock.mode == ClockMode::kRealtime && !options.simulated_time;
    dt = spec.clock.mode == ClockMode::kRealtime ? 1.0 / spec.clock.rate_hz : spec.clock.step;
    const auto& components = pipeline.components();
    for (const auto& level : levels) {
      std::vector<bool> flags;
      for (const std::size_t i : level) flags.push_back(components[i]->thread_affine());
      affine.push_back(std::move(flags));
    }
    source_index = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (pipeline.time_source() != nullptr &&
          dynamic_cast<TimeSource*>(components[i].get()) == pipeline.time_source()) {
        source_index = i;
      }
    }
    step_seconds.resize(n);
    error_counts.assign(n, 0);
    failures.resize(n);
    stepped.assign(n, 0);
    held.resize(n);
    result.timing.own.assign(n, 0.0);
    result.timing.finished.assign(n, 0.0);
  }

  void Report(const StepError& error) {
    if (options.on_error) options.on_error(error);
    ++summary.errors_total;
    if (summary.errors.size() < RunSummary::kMaxKeptErrors) summary.errors.push_back(error);
  }

  void CheckRunning(const char* who) const {
    const char* why = !started       ? "not started; call Start first"
                      : start_failed ? "a component failed to start; no step may run"
                      : stopped      ? "stopped; no step may run after Stop"
                                     : nullptr;
    if (why != nullptr) throw InvalidArgument(std::string("Stepper::") + who + ": " + why);
  }

  void PrepareNext() {
    tick_start = Clock::now();
    next = StepContext{};
    next.step = summary.steps;
    next.time = realtime_clock ? Seconds(tick_start - epoch)
                               : SimulatedStepTime(pipeline, next.step, summary.sim_time);
    // The source's wait for the step's message is its reader's time, as a Step's wait is.
    source_seconds = realtime_clock ? 0.0 : Seconds(Clock::now() - tick_start);
    next.dt = dt;
    next.realtime = realtime_clock || options.live;
    prepared = true;
  }

  // Steps one component (a task of the pool): its failure kept in failures[i].
  void StepComponent(std::size_t i, bool parallel) {
    Component& component = *pipeline.components()[i];
    failures[i] = nullptr;
    stepped[i] = 0;
    // One after the other, a failure with on_error: stop ends the step there.
    if (!component.enabled() || (!parallel && stop_now)) return;
    stepped[i] = 1;
    StepContext own_context = next;
    own_context.seed = component.seed();
    if (!parallel && options.while_waiting) own_context.while_waiting = &options.while_waiting;
    DeferredEmits*& deferred = DeferredEmits::Current();
    if (parallel) {
      deferred = &held[i];
    } else {
      pipeline.TakeDeliverySeconds();
    }
    const Clock::time_point start = Clock::now();
    try {
      component.Step(own_context);
    } catch (...) {
      failures[i] = std::current_exception();
      if (!parallel && pipeline.spec().on_error == OnError::kStop) stop_now = true;
    }
    // Serial: deliveries made while it emitted are the bus's time, not its own.
    result.timing.own[i] = std::max(
        0.0, Seconds(Clock::now() - start) - (parallel ? 0.0 : pipeline.TakeDeliverySeconds()));
    if (i == source_index) result.timing.own[i] += source_seconds;
    deferred = nullptr;
  }

  // Runs level `l`; returns its components' time (the longest, or the sum when serial).
  double RunLevel(std::size_t l) {
    const std::vector<std::size_t>& level = levels[l];
    const bool parallel = level.size() > 1 && pool->threads() > 1;
    pool->Run(
        level.size(), [&](std::size_t j) { StepComponent(level[j], parallel); }, affine[l]);
    // In execution order: the held deliveries, then the bookkeeping.
    double longest = 0.0;
    for (const std::size_t i : level) {
      Component& component = *pipeline.components()[i];
      if (!stepped[i]) {
        if (!component.enabled()) {
          for (const auto& input : component.inputs()) input->MarkSeen();
        }
        continue;
      }
      if (parallel) held[i].Deliver();
      result.timing.finished[i] = Seconds(Clock::now() - tick_start);
      for (const auto& input : component.inputs()) input->MarkSeen();
      step_seconds[i].Add(result.timing.own[i]);
      // One after the other the level takes the sum of its times, at once the longest.
      longest = parallel ? std::max(longest, result.timing.own[i]) : longest + result.timing.own[i];
      if (failures[i]) {
        StepError error{component.name(), "step", next.step, What(failures[i])};
        Report(error);
        result.errors.push_back(std::move(error));
        ++error_counts[i];
        if (pipeline.spec().on_error == OnError::kStop) stop_now = true;
      }
    }
    pipeline.TakeDeliverySeconds();
    return longest;
  }

  const StepResult& Step() {
    if (!prepared) PrepareNext();
    prepared = false;
    result.context = next;
    result.errors.clear();
    std::fill(result.timing.own.begin(), result.timing.own.end(), 0.0);
    std::fill(result.timing.finished.begin(), result.timing.finished.end(), 0.0);
    stop_now = false;
    pipeline.DeliverDelayed();
    pipeline.BeginStep(next);
    double component_seconds = 0.0;  // per level, the longest own time (the sum if serial)
    for (std::size_t l = 0; l < levels.size() && !stop_now; ++l) component_seconds += RunLevel(l);
    pipeline.EndStep(next);
    const double overhead = std::max(0.0, Seconds(Clock::now() - tick_start) - component_seconds);
    result.timing.overhead = overhead;
    overhead_seconds.Add(overhead);
    total_component += component_seconds;
    total_overhead += overhead;
    summary.steps = next.step + 1;
    summary.sim_time = next.time;
    result.stopped_on_error = stop_now;
    if (stop_now) summary.stopped_on_error = true;
    return result;
  }

  // Stops the started components, the last first; `report`: tell on_error and the summary.
  std::vector<StepError> StopAll(bool report) {
    std::vector<StepError> errors;
    if (stopped) return errors;
    stopped = true;
    const auto& components = pipeline.components();
    for (std::size_t i = started_count; i-- > 0;) {
      try {
        components[i]->Stop();
      } catch (...) {
        errors.push_back({components[i]->name(), "stop", -1, What(std::current_exception())});
        if (report) {
          Report(errors.back());
          ++error_counts[i];
        }
      }
    }
    stop_time = Clock::now();
    return errors;
  }

  Pipeline& pipeline;
  const StepperOptions options;
  const std::size_t n;
  const std::vector<std::vector<std::size_t>> levels;
  std::vector<std::vector<bool>> affine;  // per level, its thread-affine components
  std::size_t source_index = 0;           // the time source's component (n: none)
  bool realtime_clock = false;            // time from the wall clock
  double dt = 0.0;
  std::unique_ptr<internal::ThreadPool> pool;  // made by Start

  bool started = false;
  bool start_failed = false;
  bool stopped = false;
  std::size_t started_count = 0;
  Clock::time_point start_time;  // Start's beginning
  Clock::time_point epoch;       // Start's end: the real-time clock's zero
  Clock::time_point stop_time;   // Stop's end

  // The next step's, from PrepareNext.
  bool prepared = false;
  StepContext next;
  Clock::time_point tick_start;
  double source_seconds = 0.0;

  // The step's, reused.
  StepResult result;
  std::vector<std::exception_ptr> failures;
  std::vector<char> stepped;
  std::vector<DeferredEmits> held;  // each component's deliveries in a parallel level
  bool stop_now = false;

  // The run's, in constant memory however long it is (core/streaming_stats.h).
  RunSummary summary;  // steps, sim_time, stopped_on_error, errors
  std::vector<StreamingStats> step_seconds;
  std::vector<int64_t> error_counts;
  StreamingStats overhead_seconds;
  double total_component = 0.0;
  double total_overhead = 0.0;
};

Stepper::Stepper(Pipeline& pipeline, StepperOptions options)
    : impl_(std::make_unique<Impl>(pipeline, std::move(options))) {}

Stepper::~Stepper() { impl_->StopAll(/*report=*/false); }

std::optional<StepError> Stepper::Start() {
  Impl& s = *impl_;
  if (s.started) throw InvalidArgument("Stepper::Start: already started; expected one Start");
  s.started = true;
  const PipelineSpec& spec = s.pipeline.spec();
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  s.pool = std::make_unique<internal::ThreadPool>(
      spec.threads > 0 ? spec.threads : std::min(hardware, kMaxThreads));
  s.start_time = Clock::now();
  const auto& components = s.pipeline.components();
  for (; s.started_count < s.n; ++s.started_count) {
    try {
      components[s.started_count]->Start();
    } catch (...) {
      StepError error{components[s.started_count]->name(), "start", -1,
                      What(std::current_exception())};
      s.Report(error);
      ++s.error_counts[s.started_count];
      s.summary.stopped_on_error = true;
      s.start_failed = true;
      return error;
    }
  }
  s.pipeline.TakeDeliverySeconds();  // deliveries during Start are not the steps'
  s.epoch = Clock::now();
  return std::nullopt;
}

const StepContext& Stepper::Next() {
  impl_->CheckRunning("Next");
  if (!impl_->prepared) impl_->PrepareNext();
  return impl_->next;
}

const StepResult& Stepper::Step() {
  impl_->CheckRunning("Step");
  return impl_->Step();
}

std::vector<StepError> Stepper::Stop() { return impl_->StopAll(/*report=*/true); }

int64_t Stepper::steps_done() const { return impl_->summary.steps; }

RunSummary Stepper::Summary() const {
  const Impl& s = *impl_;
  RunSummary summary = s.summary;
  if (s.started) {
    summary.wall_seconds = Seconds((s.stopped ? s.stop_time : Clock::now()) - s.start_time);
  }
  const auto& components = s.pipeline.components();
  for (std::size_t i = 0; i < s.n; ++i) {
    const Stats stats = Summarise(s.step_seconds[i]);
    summary.components.push_back({components[i]->name(), s.step_seconds[i].count(), stats.mean,
                                  stats.median, stats.p95, stats.max, s.error_counts[i]});
  }
  const Stats overhead = Summarise(s.overhead_seconds);
  summary.overhead_mean_ms = overhead.mean;
  summary.overhead_median_ms = overhead.median;
  summary.overhead_p95_ms = overhead.p95;
  const double total = s.total_component + s.total_overhead;
  summary.overhead_share = total > 0.0 ? s.total_overhead / total : 0.0;
  return summary;
}

RunSummary RunPipeline(Pipeline& pipeline, const RunOptions& options) {
  const PipelineSpec& spec = pipeline.spec();
  const int64_t steps = options.steps >= 0 ? options.steps : spec.clock.steps;
  if (steps == 0 && options.stop == nullptr && !(options.seconds > 0.0)) {
    throw InvalidArgument(
        "RunPipeline: pipeline '" + spec.file +
        "' has no clock.steps and no stop flag or seconds were given: it would never end");
  }
  const bool realtime = spec.clock.mode == ClockMode::kRealtime;
  Stepper stepper(pipeline, {.simulated_time = false,
                             .live = options.live,
                             .on_error = options.on_error,
                             .while_waiting = options.while_waiting});
  int64_t overruns = 0;
  if (!stepper.Start().has_value()) {
    // Real time: the ticks' period.
    const auto period = std::chrono::round<Clock::duration>(
        std::chrono::duration<double>(1.0 / spec.clock.rate_hz));
    Clock::time_point next_tick = Clock::now();
    for (int64_t k = 0; steps == 0 || k < steps; ++k) {
      if (options.stop != nullptr && options.stop->load()) break;
      if (realtime) std::this_thread::sleep_until(next_tick);
      if (options.seconds > 0.0 && stepper.Next().time >= options.seconds) break;
      const StepResult& result = stepper.Step();
      if (options.step_timing) options.step_timing(result.context, result.timing);
      if (options.after_step) options.after_step(result.context);
      if (result.stopped_on_error) break;
      if (realtime) {
        next_tick += period;
        const Clock::time_point now = Clock::now();
        if (now > next_tick) {
          ++overruns;
          while (next_tick < now) next_tick += period;  // skip missed ticks, do not bunch
        }
      }
    }
  }
  // Every started component is stopped, the last started first.
  stepper.Stop();
  RunSummary summary = stepper.Summary();
  summary.overruns = overruns;
  return summary;
}

}  // namespace saccade::runtime
