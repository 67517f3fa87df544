// Run control (run_control.h): pause, single steps and speed, set from one thread and obeyed by
// the thread that runs the steps.

#include "saccade/runtime/run_control.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "saccade/core/error.h"

namespace saccade::runtime {
namespace {

double Seconds(std::chrono::steady_clock::time_point from) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - from).count();
}

TEST(RunControl, BadSpeedsAndStepsAreRefusedAndChangeNothing) {
  EXPECT_THROW(RunControl(false, 0.0), InvalidArgument);
  RunControl control(false, 2.0);
  EXPECT_THROW(control.SetSpeed(11.0), InvalidArgument);
  EXPECT_THROW(control.SetSpeed(std::nan("")), InvalidArgument);
  EXPECT_EQ(control.speed(), 2.0);
  try {
    control.Step(1);
    FAIL() << "a step while running was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "step: pause first (steps are for a paused simulation)");
  }
  control.Pause();
  EXPECT_THROW(control.Step(0), InvalidArgument);
  EXPECT_THROW(control.Step(RunControl::kMaxSteps + 1), InvalidArgument);
}

// Paused, the stepping thread waits; two single steps let exactly two steps through.
TEST(RunControl, PausedRunsOnlyTheStepsAsked) {
  RunControl control(/*paused=*/true, RunControl::kMaxSpeed);
  std::atomic<bool> stop{false};
  std::atomic<int> steps{0};
  std::atomic<int> waits_while_paused{0};
  std::thread runner([&] {
    for (int64_t i = 0; !stop; ++i) {
      control.WaitBeforeNext(StepContext{i, i * 1e-4, 1e-4, 0}, stop, [&](bool paused) {
        if (paused) ++waits_while_paused;
      });
      if (!stop) ++steps;
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(steps, 0);
  EXPECT_GT(waits_while_paused, 0);  // the caller gets to apply commands while paused
  control.Step(2);
  const auto asked = std::chrono::steady_clock::now();
  while (steps < 2 && Seconds(asked) < 10.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // and no third
  EXPECT_EQ(steps, 2);
  control.Resume();
  const auto resumed = std::chrono::steady_clock::now();
  while (steps <= 2 && Seconds(resumed) < 10.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_GT(steps, 2);
  stop = true;
  runner.join();
}

// At speed 2, 0.5 s of simulated time takes at least 0.25 s of wall time (a lower bound only:
// a loaded machine is slower, never faster).
TEST(RunControl, SpeedBoundsSimulatedSecondsPerWallSecond) {
  RunControl control(false, 2.0);
  std::atomic<bool> stop{false};
  const auto start = std::chrono::steady_clock::now();
  for (int64_t i = 0; i < 25; ++i) control.WaitBeforeNext(StepContext{i, i * 0.02, 0.02, 0}, stop);
  EXPECT_GE(Seconds(start), 0.25 - 0.02);
  // Stop returns at once, however far the pace is ahead.
  control.SetSpeed(RunControl::kMinSpeed);
  stop = true;
  const auto stopped = std::chrono::steady_clock::now();
  control.WaitBeforeNext(StepContext{25, 0.5, 10.0, 0}, stop);
  EXPECT_LT(Seconds(stopped), 1.0);
}

}  // namespace
}  // namespace saccade::runtime
