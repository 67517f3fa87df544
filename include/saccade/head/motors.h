#pragma once
// A head's motors, one per actuated joint (HeadModel): joint motion under the position,
// velocity and acceleration limits of the head (description vs state: the limits are copied
// from the description; the state is the joint positions and velocities). A joint the head
// does not drive (JointSettings::driven false) stays at its hold value: commands for all
// joints leave it there, a command for it alone throws.
//
// Commands, per joint or for all joints at once (by name: a JointState in another order is
// arranged in the head's), replace the joint's current motion and
// start from its current position and velocity (no need to stop first):
//   - saccade: SetTarget(position). Time-optimal point-to-point motion ending at rest on the
//     target (trapezoidal or triangular velocity profile, JointProfile).
//   - smooth pursuit: SetTarget(position, velocity). The target moves from `position` at the
//     constant `velocity` (feed-forward); the joint intercepts it time-optimally, then
//     follows it with zero lag, and stops on the limit the target runs into.
// Product rule: no motion outside the joint limits. Target positions outside [min, max] are
// clamped to them, target velocities beyond max_velocity to it; the command returns which
// joints were clamped, and clamped_commands() counts them. Non-finite targets throw
// InvalidArgument and change nothing.
//
// Step(dt) advances time; every state is evaluated in closed form from the profile
// planned at the last command, so the state at a given time does not depend on how the
// time was stepped. Positions never leave [min, max], |velocity| <= max_velocity and
// |acceleration| <= max_acceleration at all times.
//
// Not thread-safe: one owner steps and commands it.

#include <utility>
#include <vector>

#include "saccade/head/head_model.h"
#include "saccade/head/joint_profile.h"
#include "saccade/head/joint_state.h"

namespace saccade::head {

/// Which joints' last command was clamped to the limits.
struct ClampReport {
  std::vector<bool> clamped;  ///< indexed by joint
  bool operator[](int joint) const { return clamped[joint]; }
  bool any() const;
};

/// The simulated motor state of a head.
class Motors {
 public:
  /// Default tolerance of Arrived(): 1e-6 rad (0.06 mdeg, well under a pixel) and rad/s.
  static constexpr double kArrivalTolerance = 1e-6;

  /// Motors of `head` at rest at `positions` (rad; empty: the head's home posture). Throws
  /// InvalidArgument as Reset().
  explicit Motors(const HeadModel& head, const JointState& positions = {});

  /// Sets the state (rad, rad/s) and cancels the commands: each joint's target becomes
  /// where it stops when braking at the acceleration limit (its position when at rest).
  /// Throws InvalidArgument naming the joint and value when a value is not finite, a
  /// position is outside the limits, a velocity exceeds max_velocity, or the joint cannot
  /// stop before a position limit, or a joint the head holds is not at its hold value; the
  /// state is unchanged then. Empty velocities: at rest.
  void Reset(const JointState& positions, const JointState& velocities = {});

  /// Saccade of every joint to `position` (rad). Throws InvalidArgument naming the joint
  /// and value for a non-finite target, or unknown or missing joints, without changing any
  /// joint.
  ClampReport SetTarget(const JointState& position);
  /// Smooth pursuit of every joint: the target is at `position` (rad) now and moves at
  /// `velocity` (rad/s; empty: 0). Throws as above.
  ClampReport SetTarget(const JointState& position, const JointState& velocity);
  /// One joint: pursuit, or saccade when velocity is 0. Returns whether it was clamped.
  /// Throws InvalidArgument for a joint the head does not drive.
  bool SetJointTarget(int joint, double position, double velocity = 0.0);

  /// Advances the motion by dt seconds (finite, >= 0; else throws InvalidArgument).
  void Step(double dt);

  /// Joint positions now (rad).
  JointState positions() const;
  /// Joint velocities now (rad/s).
  JointState velocities() const;
  /// Joint accelerations now (rad/s^2), for motion blur and logging.
  JointState accelerations() const;
  /// Where the (clamped) targets are now (rad).
  JointState targets() const;
  /// How fast the targets move now (rad/s): a pursuit's velocities, zero for a saccade.
  JointState target_velocities() const;

  /// Whether the joint is within `tolerance` of its target in position (rad) and velocity
  /// (rad/s).
  bool Arrived(int joint, double tolerance = kArrivalTolerance) const;
  /// Whether every joint has arrived.
  bool Arrived(double tolerance = kArrivalTolerance) const;

  /// Duration (s) of the joint's current command: from the command until it reaches the
  /// target (at rest for a saccade, tracking for a pursuit). E.g. a saccade's duration.
  double CommandDuration(int joint) const;
  /// Time (s) left until the joint reaches its target; 0 once it has.
  double TimeToTarget(int joint) const;
  /// The largest TimeToTarget over the joints.
  double TimeToTarget() const;

  /// Seconds stepped since construction.
  double time() const { return time_; }
  /// Number of joint commands clamped to the limits since construction.
  int clamped_commands() const { return clamped_commands_; }
  int num_joints() const { return static_cast<int>(limits_.size()); }
  const std::shared_ptr<const JointNames>& joint_names() const { return names_; }
  const JointLimits& limits(int joint) const { return limits_[joint]; }
  bool driven(int joint) const { return driven_[joint]; }
  /// The joint's planned motion; times from its last command (see command_time()).
  const JointProfile& profile(int joint) const { return profiles_[joint]; }
  /// Seconds since the joint's last command.
  double command_time(int joint) const { return elapsed_[joint]; }

 private:
  // Validates a command; throws naming the joint. Returns the clamped values.
  std::pair<double, double> Clamp(const char* function, int joint, double position, double velocity,
                                  bool* clamped) const;
  void Command(int joint, double position, double velocity);
  JointState Arranged(const JointState& joints) const;
  template <typename F>
  JointState Each(F value) const;

  std::shared_ptr<const JointNames> names_;
  std::vector<JointLimits> limits_;  // a held joint: [hold, hold]
  std::vector<bool> driven_;
  std::vector<JointProfile> profiles_;
  std::vector<double> elapsed_;  // seconds since each joint's last command
  double time_ = 0.0;
  int clamped_commands_ = 0;
};

}  // namespace saccade::head
