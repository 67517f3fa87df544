#include "saccade/head/motors.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "saccade/core/error.h"

namespace saccade::head {

Motors::Motors(const HeadDescription& head, const JointState& positions) {
  for (Joint joint : kAllJoints) {
    limits_[Index(joint)] = head.limits(joint);
  }
  Reset(positions);
}

void Motors::Reset(const JointState& positions, const JointState& velocities) {
  // Validate everything first: a throw leaves the state unchanged.
  for (Joint joint : kAllJoints) {
    const JointLimits& l = limits_[Index(joint)];
    const double x = positions[joint];
    const double v = velocities[joint];
    if (!std::isfinite(x) || !l.Contains(x)) {
      throw InvalidArgument(
          fmt::format("Motors::Reset: {} position = {} rad, expected a finite value in [{}, {}]",
                      JointName(joint), x, l.min, l.max));
    }
    if (!std::isfinite(v) || std::abs(v) > l.max_velocity) {
      throw InvalidArgument(
          fmt::format("Motors::Reset: {} velocity = {} rad/s, expected a finite value within +-{}",
                      JointName(joint), v, l.max_velocity));
    }
    const double stop = x + v * std::abs(v) / (2 * l.max_acceleration);
    if (!l.Contains(stop)) {
      throw InvalidArgument(
          fmt::format("Motors::Reset: {} at {} rad moving at {} rad/s cannot stop before its limit "
                      "(it stops at {} rad, expected within [{}, {}])",
                      JointName(joint), x, v, stop, l.min, l.max));
    }
  }
  for (Joint joint : kAllJoints) {
    const JointLimits& l = limits_[Index(joint)];
    const double x = positions[joint];
    const double v = velocities[joint];
    const double stop = std::clamp(x + v * std::abs(v) / (2 * l.max_acceleration), l.min, l.max);
    profiles_[Index(joint)] = JointProfile::Plan(l, x, v, stop, 0.0);
    elapsed_[Index(joint)] = 0.0;
  }
}

std::pair<double, double> Motors::Clamp(const char* function, Joint joint, double position,
                                        double velocity, bool* clamped) const {
  if (!std::isfinite(position)) {
    throw InvalidArgument(
        fmt::format("Motors::{}: {} target position = {} rad, expected a finite value", function,
                    JointName(joint), position));
  }
  if (!std::isfinite(velocity)) {
    throw InvalidArgument(
        fmt::format("Motors::{}: {} target velocity = {} rad/s, expected a finite value", function,
                    JointName(joint), velocity));
  }
  const JointLimits& l = limits_[Index(joint)];
  const double x = std::clamp(position, l.min, l.max);
  const double v = std::clamp(velocity, -l.max_velocity, l.max_velocity);
  *clamped = x != position || v != velocity;
  return {x, v};
}

void Motors::Command(Joint joint, double position, double velocity) {
  const int i = Index(joint);
  const double t = elapsed_[i];
  const JointProfile& now = profiles_[i];
  // The current state is reachable from inside the limits by construction.
  profiles_[i] = JointProfile::Plan(
      limits_[i], now.Position(t),
      std::clamp(now.Velocity(t), -limits_[i].max_velocity, limits_[i].max_velocity), position,
      velocity);
  elapsed_[i] = 0.0;
}

ClampReport Motors::SetTarget(const JointState& position) {
  return SetTarget(position, JointState{});
}

ClampReport Motors::SetTarget(const JointState& position, const JointState& velocity) {
  ClampReport report;
  std::array<std::pair<double, double>, 4> clamped;
  for (Joint joint : kAllJoints) {  // validate all before moving any
    clamped[Index(joint)] =
        Clamp("SetTarget", joint, position[joint], velocity[joint], &report.clamped[Index(joint)]);
  }
  for (Joint joint : kAllJoints) {
    Command(joint, clamped[Index(joint)].first, clamped[Index(joint)].second);
    clamped_commands_ += report[joint] ? 1 : 0;
  }
  return report;
}

bool Motors::SetJointTarget(Joint joint, double position, double velocity) {
  bool was_clamped = false;
  const auto [x, v] = Clamp("SetJointTarget", joint, position, velocity, &was_clamped);
  Command(joint, x, v);
  clamped_commands_ += was_clamped ? 1 : 0;
  return was_clamped;
}

void Motors::Step(double dt) {
  if (!std::isfinite(dt) || dt < 0.0) {
    throw InvalidArgument(fmt::format("Motors::Step: dt = {} s, expected a finite value >= 0", dt));
  }
  time_ += dt;
  for (double& elapsed : elapsed_) elapsed += dt;
}

JointState Motors::positions() const {
  JointState state;
  for (Joint joint : kAllJoints)
    state[joint] = profiles_[Index(joint)].Position(elapsed_[Index(joint)]);
  return state;
}

JointState Motors::velocities() const {
  JointState state;
  for (Joint joint : kAllJoints)
    state[joint] = profiles_[Index(joint)].Velocity(elapsed_[Index(joint)]);
  return state;
}

JointState Motors::accelerations() const {
  JointState state;
  for (Joint joint : kAllJoints) {
    state[joint] = profiles_[Index(joint)].Acceleration(elapsed_[Index(joint)]);
  }
  return state;
}

JointState Motors::target_velocities() const {
  JointState state;
  for (Joint joint : kAllJoints) {
    state[joint] = profiles_[Index(joint)].TargetVelocity(elapsed_[Index(joint)]);
  }
  return state;
}

JointState Motors::targets() const {
  JointState state;
  for (Joint joint : kAllJoints) {
    state[joint] = profiles_[Index(joint)].TargetPosition(elapsed_[Index(joint)]);
  }
  return state;
}

bool Motors::Arrived(Joint joint, double tolerance) const {
  const JointProfile& p = profiles_[Index(joint)];
  const double t = elapsed_[Index(joint)];
  return std::abs(p.Position(t) - p.TargetPosition(t)) <= tolerance &&
         std::abs(p.Velocity(t) - p.TargetVelocity(t)) <= tolerance;
}

bool Motors::Arrived(double tolerance) const {
  return std::all_of(kAllJoints.begin(), kAllJoints.end(),
                     [&](Joint joint) { return Arrived(joint, tolerance); });
}

double Motors::CommandDuration(Joint joint) const { return profiles_[Index(joint)].duration(); }

double Motors::TimeToTarget(Joint joint) const {
  return std::max(0.0, profiles_[Index(joint)].duration() - elapsed_[Index(joint)]);
}

double Motors::TimeToTarget() const {
  double t = 0.0;
  for (Joint joint : kAllJoints) t = std::max(t, TimeToTarget(joint));
  return t;
}

}  // namespace saccade::head
