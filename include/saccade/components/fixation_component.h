#pragma once
// control.fixation -- turns the 3D target into joint commands (seed section 3 and appendix A:
// inverse kinematics, pan then tilt then symmetric vergence): a saccade to a new target, smooth
// pursuit (position plus the joint velocities that follow the target's motion) of a moving one.
//   params: declared in the constructor (docs/components.md lists them)
//   inputs: target (vision.target, required)
//   outputs: command (head.command), for every new valid target
//   The command is always within the joint limits (IK clamps; the motors clamp again).
#include <memory>
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/head/fixation.h"
#include "saccade/head/head_description.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

class FixationComponent : public runtime::Component {
 public:
  FixationComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  head::JointState Solve(const Eigen::Vector3d& p_W, const head::JointState& seed) const;

  runtime::Input<TargetMessage>& target_;
  runtime::Output<JointCommand>& command_;
  std::shared_ptr<const scene::Scene> scene_;
  bool pursuit_ = true;
  double min_pursuit_speed_ = 0.02;
  double smoothing_ = 0.5;
  // The previous target, for its velocity.
  std::optional<TargetMessage> previous_;
  Eigen::Vector3d velocity_W_ = Eigen::Vector3d::Zero();
  head::JointState last_joints_;
  std::optional<head::HeadDescription> appendix_a_;       // POPEYE's legacy head: appendix A
  mutable std::unique_ptr<head::FixationSolver> solver_;  // any other head
};

}  // namespace saccade::components
