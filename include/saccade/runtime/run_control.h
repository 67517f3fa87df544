#pragma once
// Run control of a pipeline that runs in simulated time: pause, single steps and speed (at
// most `speed` simulated seconds per wall second). Any thread (the GUI's commands, a script)
// sets them; the thread that runs the pipeline calls WaitBeforeNext between steps
// (RunOptions::after_step) and obeys.

#include <atomic>
#include <functional>

#include "saccade/runtime/component.h"

namespace saccade::runtime {

class RunControl {
 public:
  static constexpr double kMinSpeed = 0.05;
  static constexpr double kMaxSpeed = 10.0;
  static constexpr int kMaxSteps = 1000;  ///< single steps asked at once

  /// Throws InvalidArgument when `speed` is outside [kMinSpeed, kMaxSpeed].
  explicit RunControl(bool paused = false, double speed = 1.0);

  void Pause() { paused_ = true; }
  /// Resumes; single steps not yet run are forgotten.
  void Resume();
  /// While paused: `count` more steps, then paused again. Throws InvalidArgument when not
  /// paused or `count` is outside [1, kMaxSteps].
  void Step(int count);
  /// Throws InvalidArgument when `speed` is outside [kMinSpeed, kMaxSpeed] (or not finite).
  void SetSpeed(double speed);

  bool paused() const { return paused_; }
  double speed() const { return speed_; }

  /// On the pipeline's thread, after the step of `context`: returns when the next step may
  /// start. While paused it waits (unless single steps were asked), calling
  /// `while_waiting(true)` every 20 ms; then it keeps the pace, calling `while_waiting(false)`
  /// at least every 20 ms. A run far behind its pace (a slow renderer) is not made to catch up
  /// later. Returns at once when `stop` is set.
  void WaitBeforeNext(const StepContext& context, const std::atomic<bool>& stop,
                      const std::function<void(bool paused)>& while_waiting = {});

 private:
  std::atomic<bool> paused_{false};
  std::atomic<int> steps_to_run_{0};
  std::atomic<double> speed_{1.0};
  // The pipeline's thread only: the wall time at which the simulated time anchor_sim_ ran.
  double anchor_wall_ = -1.0;
  double anchor_sim_ = 0.0;
  double anchor_speed_ = 0.0;
};

}  // namespace saccade::runtime
