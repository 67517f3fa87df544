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

RunSummary RunPipeline(Pipeline& pipeline, const RunOptions& options) {
  const PipelineSpec& spec = pipeline.spec();
  const int64_t steps = options.steps >= 0 ? options.steps : spec.clock.steps;
  if (steps == 0 && options.stop == nullptr && !(options.seconds > 0.0)) {
    throw InvalidArgument(
        "RunPipeline: pipeline '" + spec.file +
        "' has no clock.steps and no stop flag or seconds were given: it would never end");
  }
  const bool realtime = spec.clock.mode == ClockMode::kRealtime;
  const double dt = realtime ? 1.0 / spec.clock.rate_hz : spec.clock.step;
  const auto& components = pipeline.components();
  const std::size_t n = components.size();

  RunSummary summary;
  // Constant memory however long the run (core/streaming_stats.h).
  std::vector<StreamingStats> step_seconds(n);
  StreamingStats overhead_seconds;
  StepTiming timing;  // this step's, for options.step_timing
  timing.own.assign(n, 0.0);
  timing.finished.assign(n, 0.0);
  std::vector<std::exception_ptr> failures(n);
  std::vector<char> stepped(n, 0);
  std::vector<DeferredEmits> held(n);  // each component's deliveries in a parallel level
  const std::vector<std::vector<std::size_t>> levels = Levels(pipeline);
  std::vector<std::vector<bool>> affine;
  for (const auto& level : levels) {
    std::vector<bool> flags;
    for (const std::size_t i : level) flags.push_back(components[i]->thread_affine());
    affine.push_back(std::move(flags));
  }
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  internal::ThreadPool pool(spec.threads > 0 ? spec.threads : std::min(hardware, kMaxThreads));
  std::vector<int64_t> error_counts(n, 0);
  const auto report = [&](StepError error) {
    if (options.on_error) options.on_error(error);
    ++summary.errors_total;
    if (summary.errors.size() < RunSummary::kMaxKeptErrors)
      summary.errors.push_back(std::move(error));
  };

  std::size_t source_index = n;  // the time source's component (n: none)
  for (std::size_t i = 0; i < n; ++i) {
    if (pipeline.time_source() != nullptr &&
        dynamic_cast<TimeSource*>(components[i].get()) == pipeline.time_source()) {
      source_index = i;
    }
  }

  const Clock::time_point run_start = Clock::now();
  std::size_t started = 0;
  for (; started < n; ++started) {
    try {
      components[started]->Start();
    } catch (...) {
      report({components[started]->name(), "start", -1, What(std::current_exception())});
      ++error_counts[started];
      summary.stopped_on_error = true;
      break;
    }
  }

  if (started == n) {
    pipeline.TakeDeliverySeconds();  // deliveries during Start are not the loop's
    const auto period = std::chrono::round<Clock::duration>(std::chrono::duration<double>(dt));
    const Clock::time_point loop_start = Clock::now();
    Clock::time_point next_tick = loop_start;
    double total_component = 0.0;
    double total_overhead = 0.0;
    for (int64_t k = 0; steps == 0 || k < steps; ++k) {
      if (options.stop != nullptr && options.stop->load()) break;
      if (realtime) std::this_thread::sleep_until(next_tick);
      const Clock::time_point tick_start = Clock::now();
      StepContext context;
      context.step = k;
      context.time = realtime ? Seconds(tick_start - loop_start)
                              : SimulatedStepTime(pipeline, k, summary.sim_time);
      // The source's wait for the step's message is its reader's time, as a Step's wait is.
      const double source_seconds = realtime ? 0.0 : Seconds(Clock::now() - tick_start);
      context.dt = dt;
      context.realtime = realtime || options.live;
      if (options.seconds > 0.0 && context.time >= options.seconds) break;

      pipeline.DeliverDelayed();
      pipeline.BeginStep(context);
      double component_seconds = 0.0;  // per level, the longest own time (the sum if serial)
      std::fill(timing.own.begin(), timing.own.end(), 0.0);
      std::fill(timing.finished.begin(), timing.finished.end(), 0.0);
      bool stop_now = false;
      for (const std::vector<std::size_t>& level : levels) {
        // Each component of the level: enabled ones stepped (at the same time when the
        // level has several and the pool threads), their deliveries held back meanwhile.
        const bool parallel = level.size() > 1 && pool.threads() > 1;
        pool.Run(
            level.size(),
            [&](std::size_t j) {
              const std::size_t i = level[j];
              Component& component = *components[i];
              failures[i] = nullptr;
              stepped[i] = 0;
              // One after the other, a failure with on_error: stop ends the step there.
              if (!component.enabled() || (!parallel && stop_now)) return;
              stepped[i] = 1;
              StepContext own_context = context;
              own_context.seed = component.seed();
              if (!parallel && options.while_waiting) {
                own_context.while_waiting = &options.while_waiting;
              }
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
                if (!parallel && spec.on_error == OnError::kStop) stop_now = true;
              }
              // Serial: deliveries made while it emitted are the bus's time, not its own.
              timing.own[i] = std::max(0.0, Seconds(Clock::now() - start) -
                                                (parallel ? 0.0 : pipeline.TakeDeliverySeconds()));
              if (i == source_index) timing.own[i] += source_seconds;
              deferred = nullptr;
            },
            affine[&level - levels.data()]);
        // In execution order: the held deliveries, then the bookkeeping.
        double longest = 0.0;
        for (const std::size_t i : level) {
          Component& component = *components[i];
          if (!stepped[i]) {
            if (!component.enabled()) {
              for (const auto& input : component.inputs()) input->MarkSeen();
            }
            continue;
          }
          if (parallel) held[i].Deliver();
          timing.finished[i] = Seconds(Clock::now() - tick_start);
          for (const auto& input : component.inputs()) input->MarkSeen();
          step_seconds[i].Add(timing.own[i]);
          // One after the other the level takes the sum of its times, at once the longest.
          longest = parallel ? std::max(longest, timing.own[i]) : longest + timing.own[i];
          if (failures[i]) {
            report({component.name(), "step", k, What(failures[i])});
            ++error_counts[i];
            if (spec.on_error == OnError::kStop) stop_now = true;
          }
        }
        pipeline.TakeDeliverySeconds();
        component_seconds += longest;
        if (stop_now) break;
      }
      pipeline.EndStep(context);
      const double loop = Seconds(Clock::now() - tick_start);
      const double overhead = std::max(0.0, loop - component_seconds);
      timing.overhead = overhead;
      overhead_seconds.Add(overhead);
      total_component += component_seconds;
      total_overhead += overhead;
      summary.steps = k + 1;
      summary.sim_time = context.time;
      if (options.step_timing) options.step_timing(context, timing);
      if (options.after_step) options.after_step(context);
      if (stop_now) {
        summary.stopped_on_error = true;
        break;
      }
      if (realtime) {
        next_tick += period;
        const Clock::time_point now = Clock::now();
        if (now > next_tick) {
          ++summary.overruns;
          while (next_tick < now) next_tick += period;  // skip missed ticks, do not bunch
        }
      }
    }
    const double total = total_component + total_overhead;
    summary.overhead_share = total > 0.0 ? total_overhead / total : 0.0;
  }

  // Every started component is stopped, the last started first.
  for (std::size_t i = started; i-- > 0;) {
    try {
      components[i]->Stop();
    } catch (...) {
      report({components[i]->name(), "stop", -1, What(std::current_exception())});
      ++error_counts[i];
    }
  }
  summary.wall_seconds = Seconds(Clock::now() - run_start);

  for (std::size_t i = 0; i < n; ++i) {
    const Stats stats = Summarise(step_seconds[i]);
    summary.components.push_back({components[i]->name(), step_seconds[i].count(), stats.mean,
                                  stats.median, stats.p95, stats.max, error_counts[i]});
  }
  const Stats overhead = Summarise(overhead_seconds);
  summary.overhead_mean_ms = overhead.mean;
  summary.overhead_median_ms = overhead.median;
  summary.overhead_p95_ms = overhead.p95;
  return summary;
}

}  // namespace saccade::runtime
