#include "saccade/components/fixation_component.h"

#include "components/internal_scene.h"
#include "saccade/head/kinematics.h"

namespace saccade::components {

FixationComponent::FixationComponent()
    : target_(AddInput<TargetMessage>("target", /*required=*/true)),
      command_(AddOutput<JointCommand>("command")) {
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("pursuit", &pursuit_, "follow a moving target (else saccades only)");
  DeclareParam("min_pursuit_speed_m_s", &min_pursuit_speed_,
               "slower targets get saccades: triangulation jitter is not motion")
      .Range(0.0, 1e6)
      .Unit("m/s");
  DeclareParam("velocity_smoothing", &smoothing_, "weight of the newest velocity estimate")
      .Range(0.0, 1.0);
}

void FixationComponent::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  scene_ = scene.scene;
  const head::HeadModel& head = internal::RobotOf(*scene_, scene.path).head;
  last_joints_ = scene_->robot()->initial_joints;
  // POPEYE's legacy head keeps appendix A's solver (the fast path, kinematics.h); every other
  // head the general one (fixation.h), with the head file's rule.
  appendix_a_ = head.AppendixAHead();
  solver_ = std::make_unique<head::FixationSolver>(head);
}

head::JointState FixationComponent::Solve(const Eigen::Vector3d& p_W,
                                          const head::JointState& seed) const {
  const head::HeadModel& head = scene_->robot()->head;
  const head::JointState q = head.Arrange(seed);
  // Unreachable targets give the nearest angles within the limits.
  if (appendix_a_) {
    head::IkOptions options;
    options.seed = {q[0], q[1], q[2], q[3]};
    const head::PopeyeJoints j = head::SolveFixation(*appendix_a_, p_W, options).joints;
    return head.State(Eigen::Vector4d(j.pan, j.tilt, j.left, j.right));
  }
  head::FixationOptions options;
  options.seed = q.values();
  return head.State(solver_->Solve(p_W, options).joints);
}

void FixationComponent::Step(const runtime::StepContext& context) {
  if (!target_.fresh()) return;
  const TargetMessage& target = target_.value();
  if (!target.valid || !target.p_W.allFinite()) {
    previous_.reset();
    return;
  }
  // The target's velocity, from successive points of the same target (seconds apart > 0).
  if (previous_ && previous_->target_id == target.target_id && target.time > previous_->time) {
    const Eigen::Vector3d v = (target.p_W - previous_->p_W) / (target.time - previous_->time);
    velocity_W_ = smoothing_ * v + (1.0 - smoothing_) * velocity_W_;
  } else {
    velocity_W_.setZero();
  }
  previous_ = target;

  JointCommand command;
  command.time = context.time;
  command.target_id = target.target_id;
  command.positions = Solve(target.p_W, last_joints_);
  if (pursuit_ && velocity_W_.norm() > 0.0 && velocity_W_.norm() >= min_pursuit_speed_) {
    // Joint velocities by a finite difference of the IK along the target's motion.
    constexpr double kH = 0.02;  // s
    const head::JointState ahead = Solve(target.p_W + kH * velocity_W_, command.positions);
    command.velocities = ahead.With((ahead.values() - command.positions.values()) / kH);
  } else {
    command.velocities = head::JointState(command.positions.shared_names());
  }
  last_joints_ = command.positions;
  command_.Emit(command);
}

}  // namespace saccade::components
