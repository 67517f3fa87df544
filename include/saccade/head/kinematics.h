#pragma once
// Forward and inverse kinematics of the stereo head (seed appendix A, eqs. 4-13).
// Frames and joint signs: head_description.h.

#include <Eigen/Core>
#include <optional>
#include <string>

#include "saccade/geometry/pose.h"
#include "saccade/head/head_description.h"

namespace saccade::head {

/// Every frame of the head in the world, for one joint state.
struct HeadFrames {
  geometry::Pose X_WB;         ///< head base (REP 103)
  geometry::Pose X_WN;         ///< neck, after pan (paper's axes: x left, y up, z forward)
  geometry::Pose X_WC;         ///< cyclopean frame {c}, after tilt (eq. 4)
  geometry::Pose X_WL;         ///< left eye frame {l} (eq. 5)
  geometry::Pose X_WR;         ///< right eye frame {r} (eq. 6)
  geometry::Pose X_WCamLeft;   ///< left camera optical frame (eq. 7), OpenCV axes
  geometry::Pose X_WCamRight;  ///< right camera optical frame (eq. 8), OpenCV axes
  /// Where the two optical axes meet (eq. 9 for symmetric vergence); std::nullopt when they
  /// are parallel or meet behind the eyes.
  std::optional<Eigen::Vector3d> p_WFixation;
};

/// Forward kinematics: the chain X_WB * R_paper * Ry(pan) * eq.4 * eq.5/6 * eq.7/8.
/// Does not check joint limits (the state may come from anywhere); never throws.
HeadFrames ForwardKinematics(const HeadDescription& head, const PopeyeJoints& joints);

/// The angle (rad, in [0, pi]) between each camera's optical axis and the ray from it to p_W:
/// (left, right); 0 for both means p_W is fixated. atan2(|a x t|, a . t), exact near 0.
Eigen::Vector2d AxisErrors(const HeadDescription& head, const PopeyeJoints& joints,
                           const Eigen::Vector3d& p_W);

enum class VergenceMode {
  kSymmetric,    ///< left = -right (paper); solves pan, tilt and vergence
  kIndependent,  ///< pan kept from the seed; solves tilt, left and right
};

/// Why a target cannot be fixated exactly.
enum class Reachability {
  kReachable,
  kBehind,        ///< behind the head: would need pan beyond +-90 deg or the eyes to diverge
  kTooClose,      ///< closer than the eyes can converge within their limits
  kJointLimit,    ///< a joint would leave its limits
  kDegenerate,    ///< at the cyclopean point or on an eye's rotation axis
  kNotConverged,  ///< (any head's solver, fixation.h) no posture found that fixates it
};
const char* ToString(Reachability reachability);

struct IkOptions {
  VergenceMode mode = VergenceMode::kSymmetric;
  PopeyeJoints seed;         ///< start of the iteration; pan comes from here in kIndependent
  double tolerance = 1e-12;  ///< on the joint update (rad); the result is within 1e-9 rad
  int max_iterations = 100;
};

struct IkResult {
  /// The solution; always within the joint limits. When !reachable, the nearest reachable
  /// angles: each joint clamped to its limits after the unconstrained solution.
  PopeyeJoints joints;
  Reachability reachability = Reachability::kReachable;
  bool reachable() const { return reachability == Reachability::kReachable; }
  /// Largest angle (rad) between an optical axis and the direction from that camera to the
  /// target, at `joints`.
  double axis_error = 0.0;
  int iterations = 0;
  /// Human-readable reason when !reachable (names the joint and the limit).
  std::string message;
};

/// Closed form of eqs. 10-13 (symmetric vergence). Requires D = H = 0 (delta_l, delta_r are
/// along the optical axes and do not change the fixation); throws InvalidArgument otherwise.
IkResult SolveFixationClosedForm(const HeadDescription& head, const Eigen::Vector3d& p_W);

/// General solver for any offsets (Newton's method on the kinematic chain), either mode.
IkResult SolveFixation(const HeadDescription& head, const Eigen::Vector3d& p_W,
                       const IkOptions& options = {});

}  // namespace saccade::head
