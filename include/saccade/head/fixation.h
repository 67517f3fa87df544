#pragma once
// Fixation for any head (issue 42, item 3): the posture that puts both eye cameras' optical
// axes through a target point (the seed's fixation), within the joint limits, chosen among all
// such postures by the head's FixationRule (head_model.h).
//
// The problem. For each eye camera e with optical frame (R_e, o_e) in the world, the unit ray
// to the target in the camera is u_e = R_e^T (p - o_e) / |p - o_e|; the target is fixated when
// u_e = (0, 0, 1) for both eyes. The residual r = (u_l - e_z, u_r - e_z) vanishes exactly there
// and grows with the angle off the axis up to 180 degrees, with no false zero behind a camera
// (kinematics.cc explains why this beats angular residuals far from the solution).
//
// The solver: Gauss-Newton steps in the free parameters x (the driven joints that the rule does
// not hold; a symmetric pair q_b = sign * q_a counts as one), in coordinates scaled by the
// rule's weights W, y = W^(1/2) x:
//   dy = A^+ (-r) + (I - A^+ A) (y_preferred - y),   A = dr/dy (SVD pseudo-inverse),
// the minimum-norm correction of the fixation plus the step to the rule's optimum within the
// postures that keep it (to first order). At convergence r = 0 and the rule's cost is
// stationary on the set of fixating postures: the rule's choice, not just any posture. A
// backtracking line search on |r|^2 keeps far seeds converging; a parameter at a limit that a
// step pushes outwards is frozen (an active set). Seeds, in turn until one converges: the
// options' seed (the current posture), the head's home posture, and a two-stage seed that first
// points the axis midway between the cameras at the target and then fixates.
//
// A head that cannot verge (no joint moves one camera without the other: a fixed camera pair)
// fixates by pointing its mid-axis at the target: a virtual camera at the midpoint of the two
// optical centres, turned halfway (slerp) between the two cameras' rotations. Its axis error
// replaces the two eyes'.
//
// On POPEYE (robots/popeye.yaml: the rule left = -right) this gives appendix A's solution
// (tests/head/fixation_test.cc compares it with SolveFixation of kinematics.h to 1e-9 rad).

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "saccade/head/head_model.h"
#include "saccade/head/kinematics.h"

namespace saccade::head {

struct FixationOptions {
  /// Where the search starts (size num_joints): the current posture; empty: the home posture.
  /// Joints the rule holds keep their value from here (driven ones) or their hold value.
  Eigen::VectorXd seed;
  /// The largest angle (rad) between an optical axis and the target that counts as fixated.
  double axis_tolerance = 1e-9;
  int max_iterations = 60;  ///< Gauss-Newton steps per seed
};

struct FixationResult {
  /// The posture; always finite and within the joint limits. When !reachable, the best one
  /// found (the smallest residual), clamped.
  Eigen::VectorXd joints;
  Reachability reachability = Reachability::kReachable;
  bool reachable() const { return reachability == Reachability::kReachable; }
  /// The largest angle (rad) between an optical axis (or the mid-axis) and the target.
  double axis_error = 0.0;
  int iterations = 0;     ///< Gauss-Newton steps over all seeds tried
  bool mid_axis = false;  ///< the head cannot verge: the mid-axis was pointed
  /// Why not reachable, naming the joint and its range where a limit is the reason.
  std::string message;
};

/// The solver with its workspace (no allocation per solve after the first). Not thread-safe:
/// one per thread. Keeps a reference to the head, which must outlive it.
class FixationSolver {
 public:
  explicit FixationSolver(const HeadModel& head);
  ~FixationSolver();
  FixationSolver(const FixationSolver&) = delete;
  FixationSolver& operator=(const FixationSolver&) = delete;

  /// Fixates p_W (world, m). Throws InvalidArgument when p_W is not finite or the seed has the
  /// wrong size or is not finite; an unreachable target is a result, not an exception.
  FixationResult Solve(const Eigen::Vector3d& p_W, const FixationOptions& options = {});

  /// Whether some joint moves one camera without the other (false: a fixed camera pair).
  bool can_verge() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Where two cameras' optical axes meet: the midpoint of their common perpendicular (their
/// intersection when they cross, as POPEYE's eq. 9). std::nullopt when they are parallel
/// (|sin| < 1e-12) or meet behind either optical centre.
std::optional<Eigen::Vector3d> FixationPoint(const geometry::Pose& X_WLeft,
                                             const geometry::Pose& X_WRight);

/// One solve with a solver of its own.
FixationResult SolveFixation(const HeadModel& head, const Eigen::Vector3d& p_W,
                             const FixationOptions& options = {});

/// The angle (rad, in [0, pi]) between each eye camera's optical axis and the ray from it to
/// p_W, at posture q: (left, right).
Eigen::Vector2d AxisErrors(const HeadModel& head, const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Vector3d& p_W);

}  // namespace saccade::head
