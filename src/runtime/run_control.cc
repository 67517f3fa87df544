#include "saccade/runtime/run_control.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "saccade/core/error.h"

namespace saccade::runtime {
namespace {

constexpr double kTick = 0.02;      // s: how often a waiting loop looks up
constexpr double kFarBehind = 0.5;  // s behind the pace: start the pace again from now

double WallNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void CheckSpeed(double speed) {
  if (!(speed >= RunControl::kMinSpeed && speed <= RunControl::kMaxSpeed)) {
    throw InvalidArgument(fmt::format("speed must be in [{}, {}] (simulated s per wall s), got {}",
                                      RunControl::kMinSpeed, RunControl::kMaxSpeed, speed));
  }
}

}  // namespace

RunControl::RunControl(bool paused, double speed) : paused_(paused) {
  CheckSpeed(speed);
  speed_ = speed;
}

void RunControl::Resume() {
  steps_to_run_ = 0;
  paused_ = false;
}

void RunControl::Step(int count) {
  if (count < 1 || count > kMaxSteps) {
    throw InvalidArgument(
        fmt::format("step: count must be an integer in [1, {}], got {}", kMaxSteps, count));
  }
  if (!paused_) throw InvalidArgument("step: pause first (steps are for a paused simulation)");
  steps_to_run_ += count;
}

void RunControl::SetSpeed(double speed) {
  CheckSpeed(speed);
  speed_ = speed;
}

void RunControl::WaitBeforeNext(const StepContext& context, const std::atomic<bool>& stop,
                                const std::function<void(bool paused)>& while_waiting) {
  // Pause and single steps.
  while (paused_ && !stop) {
    if (steps_to_run_ > 0) {
      --steps_to_run_;
      break;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(kTick));
    if (while_waiting) while_waiting(true);
    anchor_wall_ = -1.0;  // the pace starts again from here
  }
  // The pace: at most `speed` simulated seconds per wall second.
  const double now = WallNow();
  const double speed = speed_;
  if (anchor_wall_ < 0.0 || std::abs(speed - anchor_speed_) > 1e-12) {
    anchor_wall_ = now;
    anchor_sim_ = context.time;
    anchor_speed_ = speed;
  }
  double due = anchor_wall_ + (context.time + context.dt - anchor_sim_) / speed;
  if (due < now - kFarBehind) {
    anchor_wall_ = now;
    anchor_sim_ = context.time + context.dt;
    due = now;
  }
  while (!stop && WallNow() < due && !paused_) {
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(kTick, due - WallNow())));
    if (while_waiting) while_waiting(false);
  }
}

}  // namespace saccade::runtime
