#include "saccade/head/motors.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "saccade/core/error.h"

namespace saccade::head {

bool ClampReport::any() const {
  return std::any_of(clamped.begin(), clamped.end(), [](bool c) { return c; });
}

Motors::Motors(const HeadModel& head, const JointState& positions) : names_(head.joint_names()) {
  for (int i = 0; i < head.num_joints(); ++i) {
    const JointSettings& s = head.joint(i);
    JointLimits l = s.limits;
    if (!s.driven) {
      // Held: it never moves; positive rates keep the (motionless) profile well defined.
      l = JointLimits{s.hold, s.hold, 1.0, 1.0};
    }
    limits_.push_back(l);
    driven_.push_back(s.driven);
  }
  profiles_.resize(limits_.size());
  elapsed_.assign(limits_.size(), 0.0);
  Reset(positions.empty() ? head.Home() : positions);
}

JointState Motors::Arranged(const JointState& joints) const {
  if (joints.empty()) return JointState(names_);
  if (joints.shared_names() == names_ || joints.names() == *names_) {
    return JointState(names_, joints.values());
  }
  return joints.ArrangedAs(names_);
}

void Motors::Reset(const JointState& position_state, const JointState& velocity_state) {
  const JointState positions = Arranged(position_state);
  const JointState velocities = Arranged(velocity_state);
  // Validate everything first: a throw leaves the state unchanged.
  for (int j = 0; j < num_joints(); ++j) {
    const JointLimits& l = limits_[j];
    const double x = positions[j];
    const double v = velocities[j];
    const std::string& name = (*names_)[j];
    if (!std::isfinite(x) || !l.Contains(x)) {
      throw InvalidArgument(
          fmt::format("Motors::Reset: {} position = {} rad, expected a finite value in [{}, {}]{}",
                      name, x, l.min, l.max, driven_[j] ? "" : " (the head holds this joint)"));
    }
    if (!std::isfinite(v) || std::abs(v) > l.max_velocity || (!driven_[j] && v != 0.0)) {
      throw InvalidArgument(
          fmt::format("Motors::Reset: {} velocity = {} rad/s, expected a finite value within +-{}",
                      name, v, driven_[j] ? l.max_velocity : 0.0));
    }
    const double stop = x + v * std::abs(v) / (2 * l.max_acceleration);
    if (!l.Contains(stop)) {
      throw InvalidArgument(
          fmt::format("Motors::Reset: {} at {} rad moving at {} rad/s cannot stop before its limit "
                      "(it stops at {} rad, expected within [{}, {}])",
                      name, x, v, stop, l.min, l.max));
    }
  }
  for (int j = 0; j < num_joints(); ++j) {
    const JointLimits& l = limits_[j];
    const double x = positions[j];
    const double v = velocities[j];
    const double stop = std::clamp(x + v * std::abs(v) / (2 * l.max_acceleration), l.min, l.max);
    profiles_[j] = JointProfile::Plan(l, x, v, stop, 0.0);
    elapsed_[j] = 0.0;
  }
}

std::pair<double, double> Motors::Clamp(const char* function, int joint, double position,
                                        double velocity, bool* clamped) const {
  const std::string& name = (*names_)[joint];
  if (!std::isfinite(position)) {
    throw InvalidArgument(
        fmt::format("Motors::{}: {} target position = {} rad, expected a finite value", function,
                    name, position));
  }
  if (!std::isfinite(velocity)) {
    throw InvalidArgument(
        fmt::format("Motors::{}: {} target velocity = {} rad/s, expected a finite value", function,
                    name, velocity));
  }
  const JointLimits& l = limits_[joint];
  const double x = std::clamp(position, l.min, l.max);
  const double v = std::clamp(velocity, -l.max_velocity, l.max_velocity);
  *clamped = x != position || v != velocity;
  return {x, v};
}

void Motors::Command(int joint, double position, double velocity) {
  const double t = elapsed_[joint];
  const JointProfile& now = profiles_[joint];
  const JointLimits& l = limits_[joint];
  // The current state is reachable from inside the limits by construction.
  profiles_[joint] = JointProfile::Plan(
      l, now.Position(t), std::clamp(now.Velocity(t), -l.max_velocity, l.max_velocity), position,
      velocity);
  elapsed_[joint] = 0.0;
}

ClampReport Motors::SetTarget(const JointState& position) {
  return SetTarget(position, JointState{});
}

ClampReport Motors::SetTarget(const JointState& position_state, const JointState& velocity_state) {
  const JointState position = Arranged(position_state);
  const JointState velocity = Arranged(velocity_state);
  ClampReport report;
  report.clamped.assign(num_joints(), false);
  std::vector<std::pair<double, double>> clamped(num_joints());
  for (int j = 0; j < num_joints(); ++j) {  // validate all before moving any
    bool c = false;
    clamped[j] = Clamp("SetTarget", j, position[j], velocity[j], &c);
    report.clamped[j] = c && driven_[j];
  }
  for (int j = 0; j < num_joints(); ++j) {
    if (!driven_[j]) continue;  // held where it is
    Command(j, clamped[j].first, clamped[j].second);
    clamped_commands_ += report[j] ? 1 : 0;
  }
  return report;
}

bool Motors::SetJointTarget(int joint, double position, double velocity) {
  if (!driven_[joint]) {
    throw InvalidArgument(
        fmt::format("Motors::SetJointTarget: the head does not drive joint {}", (*names_)[joint]));
  }
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

template <typename F>
JointState Motors::Each(F value) const {
  Eigen::VectorXd v(num_joints());
  for (int j = 0; j < num_joints(); ++j) v[j] = value(profiles_[j], elapsed_[j]);
  return JointState(names_, std::move(v));
}

JointState Motors::positions() const {
  return Each([](const JointProfile& p, double t) { return p.Position(t); });
}

JointState Motors::velocities() const {
  return Each([](const JointProfile& p, double t) { return p.Velocity(t); });
}

JointState Motors::accelerations() const {
  return Each([](const JointProfile& p, double t) { return p.Acceleration(t); });
}

JointState Motors::target_velocities() const {
  return Each([](const JointProfile& p, double t) { return p.TargetVelocity(t); });
}

JointState Motors::targets() const {
  return Each([](const JointProfile& p, double t) { return p.TargetPosition(t); });
}

bool Motors::Arrived(int joint, double tolerance) const {
  const JointProfile& p = profiles_[joint];
  const double t = elapsed_[joint];
  return std::abs(p.Position(t) - p.TargetPosition(t)) <= tolerance &&
         std::abs(p.Velocity(t) - p.TargetVelocity(t)) <= tolerance;
}

bool Motors::Arrived(double tolerance) const {
  for (int j = 0; j < num_joints(); ++j) {
    if (!Arrived(j, tolerance)) return false;
  }
  return true;
}

double Motors::CommandDuration(int joint) const { return profiles_[joint].duration(); }

double Motors::TimeToTarget(int joint) const {
  return std::max(0.0, profiles_[joint].duration() - elapsed_[joint]);
}

double Motors::TimeToTarget() const {
  double t = 0.0;
  for (int j = 0; j < num_joints(); ++j) t = std::max(t, TimeToTarget(j));
  return t;
}

}  // namespace saccade::head
