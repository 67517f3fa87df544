// Running pipelines: order and delays, determinism, failures (stop / continue), real-time
// pacing, and the timing summary; the single step (Stepper) that RunPipeline loops over.

#include "saccade/runtime/scheduler.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "runtime/test_components.h"

namespace saccade::runtime {
namespace {

using testing::MakeTestRegistry;
using testing::Record;
using testing::Recorder;
using testing::Thrower;

Pipeline Load(const std::string& text) {
  static const ComponentRegistry registry = MakeTestRegistry();
  return Pipeline::LoadString(text, "run.yaml", registry);
}

TEST(SchedulerTest, ImmediateConnectionDeliversWithinTheStep) {
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 0.25, steps: 3}
components:
  - {name: source, type: test.source, params: {start: 100}}
  - {name: recorder, type: test.recorder, inputs: {in: source.out}}
)");
  const RunSummary summary = RunPipeline(pipeline);
  EXPECT_EQ(summary.steps, 3);
  EXPECT_TRUE(summary.errors.empty());
  const auto& records = pipeline.Find<Recorder>("recorder")->records;
  ASSERT_EQ(records.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(records[k].step, k);
    EXPECT_EQ(records[k].time, 0.25 * k);
    EXPECT_TRUE(records[k].fresh);
    EXPECT_EQ(records[k].value, 100.0 + k);
  }
}

TEST(SchedulerTest, DisabledComponentIsSkippedAndEmitsNothing) {
  // The GUI switches perception off this way: source stops for steps 2 and 3, recorder
  // still runs and sees no fresh value then; re-enabled, source goes on where it was.
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 1, steps: 6}
components:
  - {name: source, type: test.source, params: {start: 0}}
  - {name: recorder, type: test.recorder, inputs: {in: source.out}}
)");
  Component* source = pipeline.Find<Component>("source");
  ASSERT_NE(source, nullptr);
  RunOptions options;
  std::vector<double> source_seconds;
  options.step_timing = [&](const StepContext&, const StepTiming& timing) {
    ASSERT_EQ(timing.own.size(), 2u);
    source_seconds.push_back(timing.own[0]);
  };
  options.after_step = [&](const StepContext& context) {
    source->SetEnabled(context.step < 1 || context.step >= 3);
  };
  RunPipeline(pipeline, options);
  const auto& r = pipeline.Find<Recorder>("recorder")->records;
  ASSERT_EQ(r.size(), 6u);
  const bool fresh[] = {true, true, false, false, true, true};
  for (int k = 0; k < 6; ++k) EXPECT_EQ(r[k].fresh, fresh[k]) << "step " << k;
  EXPECT_EQ(r[3].value, 1.0);  // the last value it emitted before it was disabled
  EXPECT_EQ(source_seconds[2], 0.0);
  EXPECT_EQ(source_seconds[3], 0.0);
}

TEST(SchedulerTest, DelayedFeedbackArrivesOneStepLater) {
  // recorder runs first and reads source's output of the previous step.
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 1, steps: 4}
components:
  - name: recorder
    type: test.recorder
    inputs:
      in: {from: source.out, delay: 1}
  - {name: source, type: test.source, params: {start: 10}}
)");
  RunPipeline(pipeline);
  const auto& r = pipeline.Find<Recorder>("recorder")->records;
  ASSERT_EQ(r.size(), 4u);
  EXPECT_FALSE(r[0].has_value);
  EXPECT_FALSE(r[0].fresh);
  for (int k = 1; k < 4; ++k) {
    EXPECT_TRUE(r[k].fresh);
    EXPECT_EQ(r[k].value, 10.0 + (k - 1)) << "step " << k;
  }
}

TEST(SchedulerTest, DelayedLoopThroughTwoComponents) {
  // relay reads its own output through a delay: 1, 2, 3, ... one per step.
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 1, steps: 5}
components:
  - name: relay
    type: test.relay
    inputs: {in: {from: seeder.out, delay: 1}}
  - name: seeder
    type: test.relay
    inputs: {in: relay.out}
  - {name: recorder, type: test.recorder, inputs: {in: seeder.out}}
)");
  RunPipeline(pipeline);
  // Nothing ever starts the loop: relay has no value, so nothing is emitted.
  const auto& r = pipeline.Find<Recorder>("recorder")->records;
  ASSERT_EQ(r.size(), 5u);
  for (const Record& record : r) EXPECT_FALSE(record.has_value);
}

TEST(SchedulerTest, FreshOnlyWhenANewMessageArrived) {
  // source emits at steps 0, 2, 4; the recorder keeps the latest in between.
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 1, steps: 5}
components:
  - {name: source, type: test.source, params: {every: 2}}
  - {name: recorder, type: test.recorder, inputs: {in: source.out}}
)");
  RunPipeline(pipeline);
  const auto& r = pipeline.Find<Recorder>("recorder")->records;
  ASSERT_EQ(r.size(), 5u);
  const bool fresh[] = {true, false, true, false, true};
  const double value[] = {0, 0, 2, 2, 4};
  for (int k = 0; k < 5; ++k) {
    EXPECT_TRUE(r[k].has_value);
    EXPECT_EQ(r[k].fresh, fresh[k]) << "step " << k;
    EXPECT_EQ(r[k].value, value[k]) << "step " << k;
  }
}

std::vector<double> RandomRun(uint64_t seed) {
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 0.04, steps: 50}
seed: )" + std::to_string(seed) +
                           R"(
components:
  - {name: noise, type: test.random}
  - {name: other_noise, type: test.random}
  - {name: recorder, type: test.recorder, inputs: {in: noise.out}}
  - {name: other, type: test.recorder, inputs: {in: other_noise.out}}
)");
  RunPipeline(pipeline);
  std::vector<double> values;
  for (const char* name : {"recorder", "other"}) {
    for (const Record& r : pipeline.Find<Recorder>(name)->records) {
      values.push_back(r.value);
      values.push_back(r.time);
    }
  }
  return values;
}

TEST(SchedulerTest, SimulatedRunsAreDeterministicPerSeed) {
  const std::vector<double> a = RandomRun(1);
  const std::vector<double> b = RandomRun(1);
  const std::vector<double> c = RandomRun(2);
  ASSERT_EQ(a.size(), 200u);
  EXPECT_EQ(a, b);  // bit for bit
  EXPECT_NE(a, c);
  // Two components of the same type get different streams.
  EXPECT_NE(a[0], a[100]);
}

// One thread: the three components are one level (none reads another) and run one after the
// other, so the failing step ends at the failing component.
constexpr const char* kThrowing = R"(clock: {mode: simulated, step: 1, steps: 6}
threads: 1
on_error: ON_ERROR
components:
  - {name: before, type: test.thrower}
  - {name: camera, type: test.thrower, params: {at: 2}}
  - {name: after, type: test.thrower}
)";

std::string WithOnError(const std::string& value) {
  std::string text = kThrowing;
  text.replace(text.find("ON_ERROR"), 8, value);
  return text;
}

TEST(SchedulerTest, ThrowingComponentStopsTheRunCleanly) {
  Pipeline pipeline = Load(WithOnError("stop"));
  std::vector<std::string> reported;
  RunOptions options;
  options.on_error = [&](const StepError& e) { reported.push_back(e.ToString()); };
  const RunSummary summary = RunPipeline(pipeline, options);
  EXPECT_TRUE(summary.stopped_on_error);
  EXPECT_EQ(summary.steps, 3);  // steps 0, 1 and the failing 2
  ASSERT_EQ(summary.errors.size(), 1u);
  EXPECT_EQ(summary.errors[0].component, "camera");
  EXPECT_EQ(summary.errors[0].step, 2);
  EXPECT_EQ(summary.errors[0].message, "sensor unplugged");
  EXPECT_EQ(reported,
            (std::vector<std::string>{"component 'camera' failed at step 2: sensor unplugged"}));
  const auto* before = pipeline.Find<Thrower>("before");
  const auto* camera = pipeline.Find<Thrower>("camera");
  const auto* after = pipeline.Find<Thrower>("after");
  EXPECT_EQ(before->steps, 3);
  EXPECT_EQ(camera->steps, 3);
  EXPECT_EQ(after->steps, 2);  // the failing step ends at the failing component
  for (const Thrower* t : {before, camera, after}) {
    EXPECT_EQ(t->starts, 1);
    EXPECT_EQ(t->stops, 1);
  }
  EXPECT_EQ(summary.components[1].errors, 1);
  EXPECT_NE(summary.BriefReport().find("stopped on error"), std::string::npos);
}

TEST(SchedulerTest, ThrowingComponentInAParallelLevelStopsAfterTheLevel) {
  // Two threads: the components of the failing one's level ran beside it; the run stops after.
  std::string text = WithOnError("stop");
  text.replace(text.find("threads: 1"), 10, "threads: 2");
  Pipeline pipeline = Load(text);
  const RunSummary summary = RunPipeline(pipeline);
  EXPECT_TRUE(summary.stopped_on_error);
  EXPECT_EQ(summary.steps, 3);
  ASSERT_EQ(summary.errors.size(), 1u);
  EXPECT_EQ(summary.errors[0].component, "camera");
  EXPECT_EQ(pipeline.Find<Thrower>("after")->steps, 3);
  EXPECT_EQ(pipeline.Find<Thrower>("after")->stops, 1);
}

// Two random streams, each through a relay to a recorder: levels {a, b}, {ra, rb}, {rec_a,
// rec_b}, each level's two at the same time when there are threads.
std::vector<std::vector<double>> TwoBranchRun(int threads) {
  Pipeline pipeline = Load(fmt::format(R"(clock: {{mode: simulated, step: 1, steps: 50}}
seed: 3
threads: {}
components:
  - {{name: a, type: test.random}}
  - {{name: b, type: test.random}}
  - {{name: ra, type: test.relay, inputs: {{in: a.out}}}}
  - {{name: rb, type: test.relay, inputs: {{in: b.out}}}}
  - {{name: rec_a, type: test.recorder, inputs: {{in: ra.out}}}}
  - {{name: rec_b, type: test.recorder, inputs: {{in: rb.out}}}}
)",
                                       threads));
  RunPipeline(pipeline);
  std::vector<std::vector<double>> out;
  for (const char* name : {"rec_a", "rec_b"}) {
    std::vector<double> values;
    for (const Record& r : pipeline.Find<Recorder>(name)->records) {
      EXPECT_TRUE(r.fresh) << name << " step " << r.step;  // delivered within the step
      values.push_back(r.value);
    }
    out.push_back(values);
  }
  return out;
}

TEST(SchedulerTest, ParallelLevelsGiveTheSerialRunBitForBit) {
  const auto serial = TwoBranchRun(1);
  ASSERT_EQ(serial[0].size(), 50u);
  EXPECT_NE(serial[0], serial[1]);
  EXPECT_EQ(TwoBranchRun(2), serial);
  EXPECT_EQ(TwoBranchRun(4), serial);
}

TEST(SchedulerTest, ALevelRunsAtTheSameTimeOnThreadsAndOneAfterTheOtherOnOne) {
  // Two components that wait for each other inside Step: with two threads they meet at every
  // step; the thread-affine one always runs on the thread that runs the pipeline.
  const auto run = [](int threads, const std::string& group, int timeout_ms) {
    Pipeline pipeline = Load(fmt::format(R"(clock: {{mode: simulated, step: 1, steps: 4}}
threads: {0}
components:
  - {{name: left, type: test.rendezvous, params: {{group: {1}, timeout_ms: {2}, affine: true}}}}
  - {{name: right, type: test.rendezvous, params: {{group: {1}, timeout_ms: {2}}}}}
)",
                                         threads, group, timeout_ms));
    RunPipeline(pipeline);
    return std::pair{pipeline.Find<testing::Rendezvous>("left")->met,
                     pipeline.Find<testing::Rendezvous>("left")->threads};
  };
  const auto [met, threads] = run(2, "parallel", 10000);
  EXPECT_EQ(met, std::vector<bool>(4, true));
  EXPECT_EQ(threads, std::vector<std::thread::id>(4, std::this_thread::get_id()));
  // One thread: the first waits alone (a short timeout), and they never meet.
  EXPECT_EQ(run(1, "serial", 20).first, std::vector<bool>(4, false));
}

// RunOptions::while_waiting reaches a component only where nothing else runs beside it: every
// component of a serial run; in a run with threads, a level of one ({alone}), never one of
// several ({rec_a, rec_b, relay}).
TEST(SchedulerTest, WhileWaitingIsOfferedOnlyWhereNothingElseRuns) {
  for (const int threads : {1, 2}) {
    Pipeline pipeline = Load(fmt::format(R"(clock: {{mode: simulated, step: 1, steps: 3}}
threads: {}
components:
  - {{name: src, type: test.random}}
  - {{name: rec_a, type: test.recorder, inputs: {{in: src.out}}}}
  - {{name: rec_b, type: test.recorder, inputs: {{in: src.out}}}}
  - {{name: relay, type: test.relay, inputs: {{in: src.out}}}}
  - {{name: alone, type: test.recorder, inputs: {{in: relay.out}}}}
)",
                                         threads));
    RunOptions options;
    std::vector<std::thread::id> calls;
    options.while_waiting = [&] { calls.push_back(std::this_thread::get_id()); };
    RunPipeline(pipeline, options);
    for (const char* name : {"rec_a", "rec_b", "alone"}) {
      const auto& records = pipeline.Find<Recorder>(name)->records;
      ASSERT_EQ(records.size(), 3u) << name;
      const bool offered = threads == 1 || std::string(name) == "alone";
      for (const Record& r : records) EXPECT_EQ(r.while_waiting, offered) << name << threads;
    }
    // Three steps of three recorders, or of the one alone; on the thread that runs the loop.
    EXPECT_EQ(calls.size(), threads == 1 ? 9u : 3u);
    for (const std::thread::id& id : calls) EXPECT_EQ(id, std::this_thread::get_id());
  }
  // Without the option, nobody is offered anything.
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 1, steps: 2}
components:
  - {name: a, type: test.random}
  - {name: rec, type: test.recorder, inputs: {in: a.out}}
)");
  RunPipeline(pipeline);
  for (const Record& r : pipeline.Find<Recorder>("rec")->records) EXPECT_FALSE(r.while_waiting);
}

TEST(SchedulerTest, ThrowingComponentWithContinueCountsErrors) {
  std::string text = WithOnError("continue");
  text.replace(text.find("{at: 2}"), 7, "{at: 2, every: true}");
  Pipeline pipeline = Load(text);
  const RunSummary summary = RunPipeline(pipeline);
  EXPECT_FALSE(summary.stopped_on_error);
  EXPECT_EQ(summary.steps, 6);
  ASSERT_EQ(summary.errors.size(), 4u);  // steps 2, 3, 4, 5
  for (int i = 0; i < 4; ++i) EXPECT_EQ(summary.errors[i].step, 2 + i);
  EXPECT_EQ(summary.components[1].errors, 4);
  EXPECT_EQ(pipeline.Find<Thrower>("after")->steps, 6);
  EXPECT_EQ(pipeline.Find<Thrower>("after")->stops, 1);
}

TEST(SchedulerTest, ALongFailingRunKeepsTheFirstErrorsAndCountsThemAll) {
  // A component that fails at every step of a long run (on_error: continue): the summary keeps
  // the first kMaxKeptErrors and counts every one; the timings count every step (issue 18:
  // memory for statistics is bounded).
  std::string text = WithOnError("continue");
  text.replace(text.find("{at: 2}"), 7, "{at: 0, every: true}");
  text.replace(text.find("steps: 6"), 8, "steps: 5000");
  Pipeline pipeline = Load(text);
  int64_t reported = 0;
  RunOptions options;
  options.on_error = [&](const StepError&) { ++reported; };
  const RunSummary summary = RunPipeline(pipeline, options);
  EXPECT_EQ(summary.steps, 5000);
  EXPECT_EQ(summary.errors_total, 5000);
  EXPECT_EQ(reported, 5000);
  ASSERT_EQ(summary.errors.size(), RunSummary::kMaxKeptErrors);
  EXPECT_EQ(summary.errors.back().step, static_cast<int64_t>(RunSummary::kMaxKeptErrors) - 1);
  EXPECT_EQ(summary.components[1].steps, 5000);
  EXPECT_EQ(summary.components[1].errors, 5000);
  EXPECT_LE(summary.components[0].median_ms, summary.components[0].p95_ms);
  EXPECT_LE(summary.components[0].p95_ms, summary.components[0].max_ms);
  EXPECT_NE(summary.BriefReport().find("5000 errors"), std::string::npos) << summary.BriefReport();
}

TEST(SchedulerTest, FailingStartStopsOnlyStartedComponents) {
  class BadStart : public Component {
   public:
    void Start() override { throw std::runtime_error("no device"); }
    void Step(const StepContext&) override { ADD_FAILURE() << "stepped"; }
  };
  ComponentRegistry registry = MakeTestRegistry();
  registry.Register<BadStart>("test.bad_start");
  Pipeline pipeline = Pipeline::LoadString(R"(clock: {mode: simulated, step: 1, steps: 3}
components:
  - {name: a, type: test.thrower}
  - {name: device, type: test.bad_start}
  - {name: c, type: test.thrower}
)",
                                           "run.yaml", registry);
  const RunSummary summary = RunPipeline(pipeline);
  EXPECT_TRUE(summary.stopped_on_error);
  EXPECT_EQ(summary.steps, 0);
  ASSERT_EQ(summary.errors.size(), 1u);
  EXPECT_EQ(summary.errors[0].ToString(), "component 'device' failed in start: no device");
  EXPECT_EQ(pipeline.Find<Thrower>("a")->stops, 1);
  EXPECT_EQ(pipeline.Find<Thrower>("c")->starts, 0);
  EXPECT_EQ(pipeline.Find<Thrower>("c")->stops, 0);
}

TEST(SchedulerTest, RealTimeIsPacedByTheWallClock) {
  Pipeline pipeline = Load(R"(clock: {mode: realtime, rate_hz: 50, steps: 5}
components:
  - {name: source, type: test.source}
  - {name: recorder, type: test.recorder, inputs: {in: source.out}}
)");
  const auto start = std::chrono::steady_clock::now();
  const RunSummary summary = RunPipeline(pipeline);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(summary.steps, 5);
  // Ticks at 0, 20, 40, 60, 80 ms: the last starts no earlier than 80 ms. No upper bound.
  EXPECT_GE(elapsed, 0.080);
  const auto& r = pipeline.Find<Recorder>("recorder")->records;
  ASSERT_EQ(r.size(), 5u);
  EXPECT_GE(r[4].time, 0.080);
  for (std::size_t k = 1; k < r.size(); ++k) EXPECT_GT(r[k].time, r[k - 1].time);
}

TEST(SchedulerTest, SecondsEndTheRunOnItsClockEvenWhenStepsAreSlow) {
  // Simulated: the steps whose time is under the bound (0, 0.25), whatever clock.steps says.
  Pipeline simulated = Load(R"(clock: {mode: simulated, step: 0.25, steps: 100}
components:
  - {name: source, type: test.source}
)");
  RunOptions options;
  options.seconds = 0.5;
  EXPECT_EQ(RunPipeline(simulated, options).steps, 2);

  // Real time, each step 30 ms against a 10 ms period: 0.2 s of wall clock hold about 7 steps,
  // not the 20 that 0.2 s at 100 Hz would count, and no step starts at or after 0.2 s.
  struct Slow : Component {
    std::vector<double> times;
    void Step(const StepContext& context) override {
      times.push_back(context.time);
      std::this_thread::sleep_for(std::chrono::milliseconds(30));
    }
  };
  ComponentRegistry registry = MakeTestRegistry();
  registry.Register<Slow>("test.slow");
  Pipeline realtime = Pipeline::LoadString(R"(clock: {mode: realtime, rate_hz: 100}
components:
  - {name: slow, type: test.slow}
)",
                                           "run.yaml", registry);
  options.seconds = 0.2;
  options.steps = 0;
  const RunSummary summary = RunPipeline(realtime, options);
  const std::vector<double>& times = realtime.Find<Slow>("slow")->times;
  ASSERT_EQ(static_cast<int64_t>(times.size()), summary.steps);
  EXPECT_GE(summary.steps, 1);
  EXPECT_LE(summary.steps, 8);
  for (const double t : times) EXPECT_LT(t, 0.2);
  EXPECT_GT(summary.overruns, 0);
}

// A live run (the GUI's, paced from outside) tells components that work may finish when it
// does, on the simulated clock's times.
TEST(SchedulerTest, ALiveRunIsRealTimeToComponentsOnSimulatedTimes) {
  struct Probe : Component {
    std::vector<std::pair<double, bool>> seen;
    void Step(const StepContext& context) override {
      seen.emplace_back(context.time, context.realtime);
    }
  };
  ComponentRegistry registry = MakeTestRegistry();
  registry.Register<Probe>("test.probe");
  for (const bool live : {false, true}) {
    Pipeline pipeline = Pipeline::LoadString(R"(clock: {mode: simulated, step: 0.5, steps: 3}
components:
  - {name: probe, type: test.probe}
)",
                                             "run.yaml", registry);
    RunOptions options;
    options.live = live;
    RunPipeline(pipeline, options);
    const auto& seen = pipeline.Find<Probe>("probe")->seen;
    ASSERT_EQ(seen.size(), 3u);
    for (std::size_t k = 0; k < seen.size(); ++k) {
      EXPECT_EQ(seen[k].first, 0.5 * static_cast<double>(k));
      EXPECT_EQ(seen[k].second, live);
    }
  }
}

TEST(SchedulerTest, StopFlagEndsAnUnboundedRun) {
  Pipeline pipeline = Load(R"(components:
  - {name: source, type: test.source}
)");
  EXPECT_THROW(RunPipeline(pipeline), InvalidArgument);  // nothing would end it
  std::atomic<bool> stop{false};
  RunOptions options;
  options.stop = &stop;
  options.after_step = [&](const StepContext& context) {
    if (context.step == 9) stop = true;
  };
  EXPECT_EQ(RunPipeline(pipeline, options).steps, 10);
}

TEST(SchedulerTest, SummaryReportsComponentTimesAndOverhead) {
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 1, steps: 20}
components:
  - {name: source, type: test.source}
  - {name: recorder, type: test.recorder, inputs: {in: source.out}}
)");
  const RunSummary summary = RunPipeline(pipeline);
  ASSERT_EQ(summary.components.size(), 2u);
  for (const ComponentTiming& c : summary.components) {
    EXPECT_EQ(c.steps, 20);
    EXPECT_GE(c.mean_ms, 0.0);
    EXPECT_LE(c.median_ms, c.p95_ms);
    EXPECT_LE(c.p95_ms, c.max_ms);
  }
  EXPECT_GE(summary.overhead_mean_ms, 0.0);
  EXPECT_GE(summary.overhead_share, 0.0);
  EXPECT_LE(summary.overhead_share, 1.0);
  const std::string report = summary.FullReport();
  EXPECT_NE(report.find("recorder"), std::string::npos);
  EXPECT_NE(report.find("(outside components)"), std::string::npos);
}

// The single step (Stepper) and the loop over it (RunPipeline) give the same run.

// A pipeline with all the step has to get right: random sources (seeds), immediate and delayed
// connections, two parallel branches, a component disabled for a while and one that fails at
// steps 3 and 5 (on_error: continue).
std::string EquivalencePipeline(int threads) {
  return fmt::format(R"(clock: {{mode: simulated, step: 0.04, steps: 12}}
seed: 7
threads: {}
on_error: continue
components:
  - {{name: a, type: test.random}}
  - {{name: b, type: test.random}}
  - {{name: ra, type: test.relay, inputs: {{in: a.out}}}}
  - {{name: rb, type: test.relay, inputs: {{in: b.out}}}}
  - {{name: rec_a, type: test.recorder, inputs: {{in: ra.out}}}}
  - {{name: rec_b, type: test.recorder, inputs: {{in: rb.out}}}}
  - {{name: rec_late, type: test.recorder, inputs: {{in: {{from: loop.out, delay: 1}}}}}}
  - {{name: ra_relay, type: test.relay, inputs: {{in: ra.out}}}}
  - {{name: loop, type: test.relay, inputs: {{in: ra_relay.out}}}}
  - {{name: flaky, type: test.thrower, params: {{at: 3}}}}
  - {{name: flakier, type: test.thrower, params: {{at: 5}}}}
)",
                     threads);
}

// What a run left: every recorder's records, the throwers' counts, and the summary's
// deterministic part (not its timings).
struct RunResult {
  std::vector<std::vector<double>> records;
  std::vector<int> thrower_counts;
  int64_t steps = 0;
  double sim_time = 0.0;
  bool stopped_on_error = false;
  std::vector<std::string> errors;
  std::vector<std::pair<int64_t, int64_t>> component_steps_and_errors;
  std::vector<double> step_times;  // after_step's (RunPipeline) or StepResult's (Stepper)
  bool operator==(const RunResult&) const = default;
};

RunResult Collect(const Pipeline& pipeline, const RunSummary& summary,
                  std::vector<double> step_times) {
  RunResult result;
  for (const char* name : {"rec_a", "rec_b", "rec_late"}) {
    std::vector<double> values;
    for (const Record& r : pipeline.Find<Recorder>(name)->records) {
      values.insert(values.end(), {static_cast<double>(r.step), r.time, r.value,
                                   r.has_value ? 1.0 : 0.0, r.fresh ? 1.0 : 0.0});
    }
    result.records.push_back(std::move(values));
  }
  for (const char* name : {"flaky", "flakier"}) {
    const Thrower* t = pipeline.Find<Thrower>(name);
    result.thrower_counts.insert(result.thrower_counts.end(), {t->starts, t->steps, t->stops});
  }
  result.steps = summary.steps;
  result.sim_time = summary.sim_time;
  result.stopped_on_error = summary.stopped_on_error;
  for (const StepError& e : summary.errors) result.errors.push_back(e.ToString());
  for (const ComponentTiming& c : summary.components) {
    result.component_steps_and_errors.emplace_back(c.steps, c.errors);
  }
  result.step_times = std::move(step_times);
  return result;
}

// `a` is switched off for steps 4 to 6, through after_step or between Stepper steps.
void SwitchA(Pipeline& pipeline, int64_t step_done) {
  pipeline.Find("a")->SetEnabled(step_done < 3 || step_done >= 6);
}

RunResult RunWithRunPipeline(const std::string& text, int64_t steps) {
  Pipeline pipeline = Load(text);
  RunOptions options;
  options.steps = steps;
  std::vector<double> times;
  options.after_step = [&](const StepContext& context) {
    times.push_back(context.time);
    SwitchA(pipeline, context.step);
  };
  const RunSummary summary = RunPipeline(pipeline, options);
  return Collect(pipeline, summary, times);
}

RunResult RunWithStepper(const std::string& text, int64_t steps) {
  Pipeline pipeline = Load(text);
  Stepper stepper(pipeline);
  EXPECT_FALSE(stepper.Start().has_value());
  std::vector<double> times;
  for (int64_t k = 0; k < steps; ++k) {
    const StepResult& result = stepper.Step();
    EXPECT_EQ(result.context.step, k);
    times.push_back(result.context.time);
    SwitchA(pipeline, result.context.step);
    if (result.stopped_on_error) break;
  }
  EXPECT_TRUE(stepper.Stop().empty());
  return Collect(pipeline, stepper.Summary(), times);
}

TEST(StepperTest, StepsGiveRunPipelinesRunBitForBit) {
  for (const int threads : {1, 2, 4}) {
    const std::string text = EquivalencePipeline(threads);
    const RunResult run = RunWithRunPipeline(text, 12);
    const RunResult stepped = RunWithStepper(text, 12);
    ASSERT_EQ(run.records[0].size(), 5u * 12u) << threads;
    EXPECT_EQ(run.errors,
              (std::vector<std::string>{"component 'flaky' failed at step 3: sensor unplugged",
                                        "component 'flakier' failed at step 5: sensor unplugged"}));
    EXPECT_EQ(run.component_steps_and_errors[0].first, 9) << "a: off for steps 4 to 6";
    EXPECT_TRUE(run == stepped) << "threads " << threads;
    // And whatever the threads, the serial run's values.
    EXPECT_TRUE(stepped == RunWithStepper(EquivalencePipeline(1), 12)) << threads;
  }
}

TEST(StepperTest, AFailureWithOnErrorStopEndsTheStepAsInRunPipeline) {
  for (const int threads : {1, 2}) {
    std::string text = EquivalencePipeline(threads);
    text.replace(text.find("on_error: continue"), 18, "on_error: stop");
    const RunResult run = RunWithRunPipeline(text, 12);
    const RunResult stepped = RunWithStepper(text, 12);
    EXPECT_EQ(run.steps, 4);  // 0 to 3, the failing step
    EXPECT_TRUE(run.stopped_on_error);
    EXPECT_TRUE(run == stepped) << "threads " << threads;
  }
}

TEST(StepperTest, NextPreparesTheStepThatStepRuns) {
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 0.25, steps: 3}
components:
  - {name: source, type: test.source, params: {start: 100}}
  - {name: recorder, type: test.recorder, inputs: {in: source.out}}
)");
  Stepper stepper(pipeline);
  EXPECT_THROW(stepper.Step(), InvalidArgument);  // not started
  ASSERT_FALSE(stepper.Start().has_value());
  EXPECT_THROW(stepper.Start(), InvalidArgument);
  for (int k = 0; k < 3; ++k) {
    const StepContext next = stepper.Next();
    EXPECT_EQ(next.step, k);
    EXPECT_EQ(next.time, 0.25 * k);
    EXPECT_EQ(next.dt, 0.25);
    EXPECT_FALSE(next.realtime);
    EXPECT_EQ(stepper.Next().step, k);  // prepared once
    const StepResult& result = stepper.Step();
    EXPECT_EQ(result.context.step, k);
    EXPECT_EQ(result.context.time, next.time);
    EXPECT_TRUE(result.errors.empty());
    EXPECT_FALSE(result.stopped_on_error);
    ASSERT_EQ(result.timing.own.size(), 2u);
    EXPECT_GT(result.timing.finished[1], 0.0);
    EXPECT_EQ(stepper.steps_done(), k + 1);
  }
  const auto& records = pipeline.Find<Recorder>("recorder")->records;
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[2].value, 102.0);
  EXPECT_TRUE(stepper.Stop().empty());
  EXPECT_THROW(stepper.Step(), InvalidArgument);  // stopped
  const RunSummary summary = stepper.Summary();
  EXPECT_EQ(summary.steps, 3);
  EXPECT_EQ(summary.sim_time, 0.5);
  EXPECT_GE(summary.wall_seconds, 0.0);
  ASSERT_EQ(summary.components.size(), 2u);
  EXPECT_EQ(summary.components[1].steps, 3);
}

TEST(StepperTest, SimulatedTimeOnARealTimePipelineIsTheCallersPace) {
  // Python's Pipeline.step: step * dt and realtime false, however slowly the steps come.
  Pipeline pipeline = Load(R"(clock: {mode: realtime, rate_hz: 4}
components:
  - {name: source, type: test.source}
  - {name: recorder, type: test.recorder, inputs: {in: source.out}}
)");
  StepperOptions options;
  options.simulated_time = true;
  Stepper stepper(pipeline, options);
  ASSERT_FALSE(stepper.Start().has_value());
  for (int k = 0; k < 3; ++k) {
    const StepResult& result = stepper.Step();
    EXPECT_EQ(result.context.time, 0.25 * k);
    EXPECT_EQ(result.context.dt, 0.25);
    EXPECT_FALSE(result.context.realtime);
  }
  stepper.Stop();
}

TEST(StepperTest, AFailedStartIsReturnedAndStopStopsOnlyTheStarted) {
  class BadStart : public Component {
   public:
    void Start() override { throw std::runtime_error("no device"); }
    void Step(const StepContext&) override { ADD_FAILURE() << "stepped"; }
  };
  class BadStop : public Component {
   public:
    void Step(const StepContext&) override {}
    void Stop() override { throw std::runtime_error("stuck"); }
  };
  ComponentRegistry registry = MakeTestRegistry();
  registry.Register<BadStart>("test.bad_start");
  registry.Register<BadStop>("test.bad_stop");
  Pipeline pipeline = Pipeline::LoadString(R"(clock: {mode: simulated, step: 1, steps: 3}
components:
  - {name: a, type: test.thrower}
  - {name: stuck, type: test.bad_stop}
  - {name: device, type: test.bad_start}
  - {name: c, type: test.thrower}
)",
                                           "run.yaml", registry);
  std::vector<std::string> told;
  StepperOptions options;
  options.on_error = [&](const StepError& e) { told.push_back(e.ToString()); };
  Stepper stepper(pipeline, options);
  const std::optional<StepError> failure = stepper.Start();
  ASSERT_TRUE(failure.has_value());
  EXPECT_EQ(failure->ToString(), "component 'device' failed in start: no device");
  EXPECT_THROW(stepper.Step(), InvalidArgument);
  const std::vector<StepError> stop_errors = stepper.Stop();
  ASSERT_EQ(stop_errors.size(), 1u);
  EXPECT_EQ(stop_errors[0].ToString(), "component 'stuck' failed in stop: stuck");
  EXPECT_TRUE(stepper.Stop().empty());  // once
  EXPECT_EQ(pipeline.Find<Thrower>("a")->stops, 1);
  EXPECT_EQ(pipeline.Find<Thrower>("c")->starts, 0);
  EXPECT_EQ(pipeline.Find<Thrower>("c")->stops, 0);
  EXPECT_EQ(told, (std::vector<std::string>{"component 'device' failed in start: no device",
                                            "component 'stuck' failed in stop: stuck"}));
  const RunSummary summary = stepper.Summary();
  EXPECT_TRUE(summary.stopped_on_error);
  EXPECT_EQ(summary.errors_total, 2);
}

TEST(StepperTest, TheDestructorStopsWhatIsStillStarted) {
  Pipeline pipeline = Load(R"(clock: {mode: simulated, step: 1, steps: 3}
components:
  - {name: a, type: test.thrower}
)");
  {
    Stepper stepper(pipeline);
    ASSERT_FALSE(stepper.Start().has_value());
    stepper.Step();
  }
  EXPECT_EQ(pipeline.Find<Thrower>("a")->steps, 1);
  EXPECT_EQ(pipeline.Find<Thrower>("a")->stops, 1);
}

}  // namespace
}  // namespace saccade::runtime
