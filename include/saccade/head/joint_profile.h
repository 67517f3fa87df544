#pragma once
// Time-optimal motion of one joint under velocity and acceleration limits.
//
// A profile is a short list of constant-acceleration segments (acceleration +-a or 0), so
// position, velocity and acceleration are evaluated in closed form at any time: stepping
// in 1 ms or in one big step gives the same state (no Euler integration).
//
// Saccade (target velocity 0): the classical time-optimal point-to-point motion from any
// start velocity to rest at the target: accelerate at the limit, cruise at the velocity
// limit if the distance is long enough (trapezoid) or not (triangle), brake at the limit.
// From rest over a distance d: t = 2 sqrt(d/a) when d <= v^2/a, else t = d/v + v/a.
// It overshoots only when the start velocity is too high to stop at the target.
//
// Pursuit (target velocity != 0): the target moves as x_t(t) = p + v_t t. In the frame
// moving with the target the same time-optimal problem is solved with the asymmetric
// velocity limits [-v_max - v_t, v_max - v_t] (so the joint never exceeds v_max); once it
// has intercepted the target it follows it exactly (zero lag: the feed-forward velocity is
// v_t). Before the target leaves the position range, the joint brakes at the acceleration
// limit so as to stop exactly on the limit the target is heading to, and stays there. When
// the intercept itself would leave the position range (a fast start near a limit), or the
// target cannot be caught before that braking point, the joint goes straight to that limit.
//
// Position limits: a profile never leaves [min, max] provided its start state can stop
// inside them (x0 + v0|v0|/(2a) in [min, max]); every profile keeps that property, so a
// chain of profiles (re-planned at each command) never leaves the range either.
// Times are seconds from the start of the profile.

#include <array>

#include "saccade/head/head_description.h"

namespace saccade::head {

/// One joint's planned motion from a start state towards a (possibly moving) target.
/// Copyable value; not thread-safe (no shared state, so distinct objects are independent).
class JointProfile {
 public:
  /// A joint at rest at `position` (rad), forever.
  explicit JointProfile(double position = 0.0);

  /// Plans the time-optimal motion from (position x0 rad, velocity v0 rad/s) to the target
  /// moving as target + target_velocity * t (rad, rad/s); target_velocity 0 is a saccade.
  /// Preconditions (checked by SACCADE_ASSERT, the caller validates user input): every
  /// value finite, limits valid (min < max, velocity and acceleration limits > 0),
  /// target in [min, max], |target_velocity| <= max_velocity, |v0| <= max_velocity, and
  /// the start state can stop within [min, max].
  static JointProfile Plan(const JointLimits& limits, double x0, double v0, double target,
                           double target_velocity);

  double Position(double t) const;      ///< rad
  double Velocity(double t) const;      ///< rad/s
  double Acceleration(double t) const;  ///< rad/s^2 (the segment's, right-continuous)
  /// Where the target is at time t (rad): for a pursuit the moving target, stopped at the
  /// position limit it is heading to; for a saccade the fixed target.
  double TargetPosition(double t) const;
  /// The target's velocity at time t (rad/s), consistent with TargetPosition.
  double TargetVelocity(double t) const;

  /// Time (s) at which the joint reaches the target: at rest on it for a saccade, moving
  /// with it for a pursuit (then it tracks it exactly). 0 for a joint already there.
  double duration() const { return duration_; }
  /// True when the plan had to give up the moving target for the limit it heads to.
  bool cut_at_limit() const { return cut_at_limit_; }

 private:
  struct Segment {
    double t0 = 0.0;  // start time
    double x0 = 0.0;  // position at t0
    double v0 = 0.0;  // velocity at t0
    double a = 0.0;   // constant acceleration over the segment
  };
  // At most: intercept (3), tracking, braking onto the limit.
  static constexpr int kMaxSegments = 5;

  void Add(double duration, double a);  // appends a segment after the last one
  int SegmentAt(double t) const;        // -1: in the tail
  bool WithinRange() const;             // whether the segments stay in [min_, max_]

  std::array<Segment, kMaxSegments> segments_{};
  int count_ = 0;
  double min_;  // position limits (+-inf for a default profile)
  double max_;
  double start_x_;
  double start_v_ = 0.0;
  double end_time_ = 0.0;  // the tail (at rest on tail_x_) starts here
  double tail_x_;
  // Target: x = target_x_ + target_v_ * t until target_stop_t_, then at rest on the limit.
  double target_x_;
  double target_v_ = 0.0;
  double target_stop_t_ = 0.0;
  double duration_ = 0.0;
  bool cut_at_limit_ = false;
};

}  // namespace saccade::head
