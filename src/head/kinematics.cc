#include "saccade/head/kinematics.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/core/units.h"

namespace saccade::head {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using geometry::Pose;

constexpr double kPi = std::numbers::pi;
// Optical axes whose directions differ by less than this (sine of the angle) are parallel:
// they would meet more than B / 1e-12 (1e11 m for B = 0.1 m) away.
constexpr double kParallelSine = 1e-12;
// A target this close (metres) to the cyclopean point or to an eye's rotation axis leaves the
// corresponding angles undefined.
constexpr double kDegenerateDistance = 1e-9;
// Newton from the seed must land on the canonical branch found geometrically (radians);
// branches differ by at least ~pi/2, so any small number separates them.
constexpr double kSameBranch = 1e-6;
// Newton steps are capped (radians per joint) so that a far seed cannot overshoot to
// another branch through the +-pi wrap of the residuals.
constexpr double kMaxStep = 0.5;
// Residuals (unit-vector components) at which double precision cannot improve further.
constexpr double kResidualFloor = 1e-15;
// Backtracking halvings before a step is given up as not decreasing the merit.
constexpr int kMaxHalvings = 30;
// Away from a solution (merit above 1e-6, i.e. axes more than ~1e-3 rad off), a step that
// lowers the merit by less than this fraction is stagnation at a local minimum. Near the
// solution convergence is quadratic and the merit drops by orders of magnitude per step.
constexpr double kStagnationMerit = 1e-6;
constexpr double kStagnationDecrease = 1e-4;

// The paper's axes (x left, y up, z forward) in the REP 103 base B (x forward, y left, z up).
const Matrix3d& PaperToBase() {
  static const Matrix3d R = (Matrix3d() << 0, 0, 1,  //
                             1, 0, 0,                //
                             0, 1, 0)
                                .finished();
  return R;
}

Pose Translation(double x, double y, double z) {
  Pose X = Pose::Identity();
  X.translation() = Vector3d(x, y, z);
  return X;
}
Pose RotX(double angle) {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(angle, Vector3d::UnitX()).toRotationMatrix();
  return X;
}
Pose RotY(double angle) {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(angle, Vector3d::UnitY()).toRotationMatrix();
  return X;
}
// Eqs. 7-8: the optical frame is the eye frame turned half a turn about z (x right, y down),
// `delta` ahead along the optical axis.
Pose EyeToCamera(double delta) {
  Pose X = Translation(0.0, 0.0, delta);
  X.linear() = Vector3d(-1.0, -1.0, 1.0).asDiagonal();
  return X;
}

double Wrap(double angle) { return std::remainder(angle, 2.0 * kPi); }

double Deg(double radians) { return radians * kRadToDeg; }

// The paper's base frame {b}: the head base B with the paper's axes.
Pose PaperBase(const HeadDescription& head) {
  return head.X_WB() * geometry::MakePose(PaperToBase(), Vector3d::Zero());
}

// Where the optical axes meet in {c}; both lie in {c}'s xz plane (the eyes turn about {c}'s
// y axis and sit on its x axis). std::nullopt when parallel or meeting behind a camera.
std::optional<Vector3d> FixationInCyclopean(const HeadGeometry& g, double left, double right) {
  const Eigen::Vector2d d_l(std::sin(left), std::cos(left));  // (x, z)
  const Eigen::Vector2d d_r(std::sin(right), std::cos(right));
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
  };
  const double denominator = cross(d_l, d_r);  // sin(left - right)
  if (std::abs(denominator) < kParallelSine) return std::nullopt;
  // Eye centres (B, 0) and (-B, 0); e_l + s d_l = e_r + t d_r.
  const Eigen::Vector2d between(-2.0 * g.B, 0.0);  // e_r - e_l
  const double s = cross(between, d_r) / denominator;
  const double t = cross(between, d_l) / denominator;
  // Distances along the axes from each camera (delta ahead of its eye centre, eqs. 7-8).
  if (!(s > g.delta_l) || !(t > g.delta_r)) return std::nullopt;
  return Vector3d(g.B + s * d_l.x(), 0.0, s * d_l.y());
}

// ---------------------------------------------------------------------------------------
// Inverse kinematics.

// The unknowns of each mode as a vector, and back.
Vector3d Unknowns(const PopeyeJoints& q, VergenceMode mode) {
  if (mode == VergenceMode::kSymmetric) return {q.pan, q.tilt, 0.5 * (q.right - q.left)};
  return {q.tilt, q.left, q.right};
}
PopeyeJoints FromUnknowns(const Vector3d& x, VergenceMode mode, double pan) {
  if (mode == VergenceMode::kSymmetric) return {x[0], x[1], -x[2], x[2]};
  return {pan, x[0], x[1], x[2]};
}

struct Linearization {
  Eigen::Matrix<double, 6, 1> residual;  // u - e_z for each camera
  Eigen::Matrix<double, 6, 3> J;         // d residual / d unknowns
  bool valid = false;
};

// Residuals: for each camera, u - e_z, where u is the unit direction from the camera to the
// target in its optical frame. They vanish exactly when both optical axes pass through the
// target in front of the cameras, and |u - e_z|^2 = 2 - 2 cos(angle off the axis) grows with
// the angle up to 180 degrees: no false zero behind the camera, so the line search below
// converges from far seeds (angular residuals such as atan2 wrap at +-180 degrees and make
// Gauss-Newton oscillate when the seed leaves the target behind the cameras).
// Jacobian analytic: a revolute joint with world axis w through a turns the frames after it,
// so the target in a camera frame moves by dt/dq = -R_WCam^T (w x (p - a)), and
// du/dq = (I - u u^T) dt/dq / |t|.
Linearization Linearize(const HeadDescription& head, const Vector3d& p_W, const PopeyeJoints& q,
                        VergenceMode mode) {
  const HeadFrames f = ForwardKinematics(head, q);
  const HeadGeometry& g = head.geometry();
  struct Axis {
    Vector3d w;
    Vector3d a;
  };
  const Axis pan{f.X_WN.linear().col(1), f.X_WN.translation()};
  const Axis tilt{f.X_WN.linear().col(0), f.X_WN * Vector3d(0.0, g.D, 0.0)};
  const Axis left{f.X_WL.linear().col(1), f.X_WL.translation()};
  const Axis right{f.X_WR.linear().col(1), f.X_WR.translation()};

  Linearization lin;
  lin.J.setZero();
  const Pose* cameras[2] = {&f.X_WCamLeft, &f.X_WCamRight};
  for (int k = 0; k < 2; ++k) {
    const Pose& X = *cameras[k];
    const Vector3d t = X.inverse() * p_W;
    const double distance = t.norm();
    if (!(distance > 0.0)) return lin;  // target at the optical centre
    const Vector3d u = t / distance;
    lin.residual.segment<3>(3 * k) = u - Vector3d::UnitZ();
    const Matrix3d project = (Matrix3d::Identity() - u * u.transpose()) / distance;
    const auto column = [&](const Axis& axis) -> Vector3d {
      return project * -(X.linear().transpose() * axis.w.cross(p_W - axis.a));
    };
    const Axis& eye = k == 0 ? left : right;
    if (mode == VergenceMode::kSymmetric) {
      // The vergence v turns the left eye by -v and the right by +v.
      lin.J.block<3, 1>(3 * k, 0) = column(pan);
      lin.J.block<3, 1>(3 * k, 1) = column(tilt);
      lin.J.block<3, 1>(3 * k, 2) = (k == 0 ? -1.0 : 1.0) * column(eye);
    } else {
      lin.J.block<3, 1>(3 * k, 0) = column(tilt);
      lin.J.block<3, 1>(3 * k, 1 + k) = column(eye);
    }
  }
  lin.valid = lin.residual.allFinite() && lin.J.allFinite();
  return lin;
}

struct NewtonOutcome {
  PopeyeJoints joints;
  bool converged = false;
  int iterations = 0;
};

// Gauss-Newton (a zero-residual problem: quadratic convergence near the solution) with the
// minimum-norm step where the Jacobian is rank deficient (target on the pan axis), each step
// capped and backtracked until the merit |residual|^2 decreases; stops early when it stagnates.
NewtonOutcome Newton(const HeadDescription& head, const Vector3d& p_W, const PopeyeJoints& start,
                     const IkOptions& options) {
  NewtonOutcome out;
  Vector3d x = Unknowns(start, options.mode);
  const double pan = start.pan;
  const auto linearize = [&](const Vector3d& at) {
    return Linearize(head, p_W, FromUnknowns(at, options.mode, pan), options.mode);
  };
  Linearization lin = linearize(x);
  for (int i = 1; i <= options.max_iterations && lin.valid; ++i) {
    out.iterations = i;
    if (lin.residual.cwiseAbs().maxCoeff() <= kResidualFloor) {
      out.converged = true;
      break;
    }
    Vector3d step = lin.J.completeOrthogonalDecomposition().solve(-lin.residual);
    if (!step.allFinite()) break;
    const double largest = step.cwiseAbs().maxCoeff();
    if (largest <= options.tolerance) {
      x += step;
      out.converged = true;
      break;
    }
    if (largest > kMaxStep) step *= kMaxStep / largest;
    const double merit = lin.residual.squaredNorm();
    Linearization next = linearize(x + step);
    for (int halving = 0;
         halving < kMaxHalvings && next.valid && !(next.residual.squaredNorm() < merit);
         ++halving) {
      step *= 0.5;
      next = linearize(x + step);
    }
    if (!next.valid || !(next.residual.squaredNorm() < merit)) break;  // stuck: not a solution
    // Creeping along a local minimum that is not a solution (merit ~ 2 - 2 cos of a large
    // angle): give up early; the caller restarts from the geometric solution.
    if (merit > kStagnationMerit &&
        next.residual.squaredNorm() > (1.0 - kStagnationDecrease) * merit) {
      x += step;
      break;
    }
    x += step;
    lin = next;
  }
  for (int i = 0; i < 3; ++i) x[i] = Wrap(x[i]);
  out.joints = FromUnknowns(x, options.mode, pan);
  return out;
}

// The exact unconstrained solution by geometry (any D, H, deltas: the deltas lie along the
// optical axes and do not move them). Used to pick the canonical branch, to restart Newton
// when it leaves that branch, and as the nearest angles when no exact solution exists.
struct Geometric {
  PopeyeJoints joints;
  bool exact = true;        // an exact solution exists (perhaps outside the limits)
  bool degenerate = false;  // at the cyclopean point or on an eye's rotation axis
  bool too_close = false;   // within H of the tilt axis: the eye plane cannot contain it
  std::string note;
};

Geometric SolveGeometrically(const HeadDescription& head, const Vector3d& p_b,
                             const IkOptions& options) {
  const HeadGeometry& g = head.geometry();
  Geometric out;
  const JointLimits& pan_limits = head.limits(Joint::kPan);
  double pan = std::clamp(options.seed.pan, pan_limits.min, pan_limits.max);
  const double rho = std::hypot(p_b.x(), p_b.z());
  if (options.mode == VergenceMode::kSymmetric) {
    // Eq. 12 generalised: the fixation lies on {c}'s z axis, which pan keeps in the plane
    // x_n = 0. On the pan axis (rho = 0) any pan will do: keep the seed's.
    if (rho > 0.0) pan = std::atan2(p_b.x(), p_b.z());
  }
  // The target in {n} relative to the tilt axis, in the (y, z) plane.
  const Vector3d p_n = RotY(pan).linear().transpose() * p_b;
  const double wy = p_n.y() - g.D;
  const double wz = p_n.z();
  const double r = std::hypot(wy, wz);
  // On the tilt axis (r = 0) any tilt will do: keep the seed's.
  const JointLimits& tilt_limits = head.limits(Joint::kTilt);
  const double seed_tilt = std::clamp(options.seed.tilt, tilt_limits.min, tilt_limits.max);
  const bool on_tilt_axis = r < kDegenerateDistance;
  const double phi = std::atan2(wz, wy);
  out.joints.pan = pan;
  if (r < std::abs(g.H)) {
    // No tilt brings the target into the eye plane, which stays H from the tilt axis.
    out.exact = false;
    out.too_close = true;
    out.note = fmt::format(
        "the target is {:.6g} m from the tilt axis, within H = {:.6g} m where the eyes' plane "
        "cannot contain it; ",
        r, std::abs(g.H));
  }
  const double in_plane = std::acos(std::clamp(g.H / std::max(r, 1e-300), -1.0, 1.0));
  if (options.mode == VergenceMode::kSymmetric) {
    // Rx(tilt) (H, f) = (wy, wz) with f the fixation distance along {c}'s z (eq. 9).
    const double f = std::sqrt(std::max(r * r - g.H * g.H, 0.0));
    out.joints.tilt = on_tilt_axis ? seed_tilt : Wrap(phi - in_plane);
    if (out.exact && f < kDegenerateDistance) {
      out.exact = false;
      out.degenerate = true;
      out.note = "the target is at the cyclopean point: pan, tilt and vergence are undefined; ";
      out.joints.pan = std::clamp(options.seed.pan, pan_limits.min, pan_limits.max);
      out.joints.tilt = seed_tilt;
    }
    const double v = std::atan2(g.B, f);  // eq. 11: tan(v) = B / f
    out.joints.left = -v;
    out.joints.right = v;
    return out;
  }
  // Independent: tilt brings the target into the eye plane (y_c = 0), in front of the eyes
  // when the head can (|tilt| <= pi/2), else behind them.
  double tilt = on_tilt_axis ? seed_tilt : Wrap(phi - in_plane);
  if (std::abs(tilt) > 0.5 * kPi) tilt = Wrap(phi + in_plane);
  out.joints.tilt = tilt;
  const Vector3d p_c =
      RotX(tilt).linear().transpose() * Vector3d(p_n.x(), wy, wz) - Vector3d(0.0, g.H, 0.0);
  out.joints.left = std::atan2(p_c.x() - g.B, p_c.z());
  out.joints.right = std::atan2(p_c.x() + g.B, p_c.z());
  if (out.exact && (std::hypot(p_c.x() - g.B, p_c.z()) < kDegenerateDistance ||
                    std::hypot(p_c.x() + g.B, p_c.z()) < kDegenerateDistance)) {
    out.exact = false;
    out.degenerate = true;
    out.note = "the target is on an eye's rotation axis: that eye's angle is undefined; ";
  }
  return out;
}

bool SameBranch(const PopeyeJoints& a, const PopeyeJoints& b) {
  for (const Joint joint : kAllJoints) {
    if (!(std::abs(Wrap(a[joint] - b[joint])) <= kSameBranch)) return false;
  }
  return true;
}

double AxisError(const HeadDescription& head, const Vector3d& p_W, const PopeyeJoints& q) {
  return AxisErrors(head, q, p_W).maxCoeff();
}

// Clamps the unconstrained solution to the limits and says why the target is not reachable.
IkResult Finish(const HeadDescription& head, const Vector3d& p_W, const PopeyeJoints& wanted,
                VergenceMode mode, bool degenerate, bool too_close, const std::string& note) {
  IkResult result;
  PopeyeJoints q = wanted;
  std::string violations;
  bool behind = false;
  bool eyes_too_converged = false;
  for (const Joint joint : kAllJoints) {
    const JointLimits& l = head.limits(joint);
    if (l.Contains(wanted[joint])) continue;
    const double clamped = std::clamp(wanted[joint], l.min, l.max);
    violations += fmt::format(
        "{}{} would need {:.3f} deg, outside its limits [{:.3f}, {:.3f}] deg (clamped to {:.3f} "
        "deg)",
        violations.empty() ? "" : "; ", JointName(joint), Deg(wanted[joint]), Deg(l.min),
        Deg(l.max), Deg(clamped));
    const bool is_eye = joint == Joint::kLeft || joint == Joint::kRight;
    if (joint == Joint::kPan && std::abs(wanted.pan) > 0.5 * kPi) behind = true;
    // Independent eyes may have to look backwards; symmetric ones never (0 < v <= pi/2).
    if (is_eye && mode == VergenceMode::kIndependent && std::abs(wanted[joint]) >= 0.5 * kPi) {
      behind = true;
    }
    if (is_eye && mode == VergenceMode::kSymmetric) eyes_too_converged = true;
  }
  if (mode == VergenceMode::kSymmetric) {
    // Keep left = -right: clamp the vergence to the range both eyes allow.
    const JointLimits& l = head.limits(Joint::kLeft);
    const JointLimits& r = head.limits(Joint::kRight);
    const double v = std::clamp(wanted.right, std::max(r.min, -l.max), std::min(r.max, -l.min));
    q.left = -v;
    q.right = v;
  } else {
    const JointLimits& l = head.limits(Joint::kLeft);
    const JointLimits& r = head.limits(Joint::kRight);
    eyes_too_converged = (!l.Contains(wanted.left) || !r.Contains(wanted.right)) &&
                         wanted.right - wanted.left > r.max - l.min;
  }
  for (const Joint joint : {Joint::kPan, Joint::kTilt}) {
    q[joint] = std::clamp(wanted[joint], head.limits(joint).min, head.limits(joint).max);
  }
  if (mode == VergenceMode::kIndependent) {
    q.left = std::clamp(wanted.left, head.limits(Joint::kLeft).min, head.limits(Joint::kLeft).max);
    q.right =
        std::clamp(wanted.right, head.limits(Joint::kRight).min, head.limits(Joint::kRight).max);
  }
  SACCADE_ASSERT(head.WithinLimits(q), "IK result outside the joint limits");

  if (degenerate) {
    result.reachability = Reachability::kDegenerate;
  } else if (behind) {
    result.reachability = Reachability::kBehind;
  } else if (too_close || eyes_too_converged) {
    result.reachability = Reachability::kTooClose;
  } else if (!violations.empty()) {
    result.reachability = Reachability::kJointLimit;
  }
  if (result.reachability != Reachability::kReachable) {
    std::string reason;
    switch (result.reachability) {
      case Reachability::kBehind:
        reason = "the target is behind the head: ";
        break;
      case Reachability::kTooClose:
        reason = "the target is too close for the eyes to converge: ";
        break;
      case Reachability::kJointLimit:
        reason = "the target is beyond a joint limit: ";
        break;
      default:
        break;
    }
    result.message = reason + note + (violations.empty() ? "" : violations);
  }
  result.joints = q;
  result.axis_error = AxisError(head, p_W, q);
  return result;
}

void CheckTarget(const char* function, const Vector3d& p_W) {
  if (!p_W.allFinite()) {
    throw InvalidArgument(fmt::format("{}: the target p_W must be finite, got ({}, {}, {})",
                                      function, p_W.x(), p_W.y(), p_W.z()));
  }
}

}  // namespace

HeadFrames ForwardKinematics(const HeadDescription& head, const PopeyeJoints& joints) {
  const HeadGeometry& g = head.geometry();
  HeadFrames f;
  f.X_WB = head.X_WB();
  f.X_WN = PaperBase(head) * RotY(joints.pan);
  // Eq. 4, then the eye baseline H above the tilt axis ({c} is the cyclopean point).
  f.X_WC = f.X_WN * Translation(0.0, g.D, 0.0) * RotX(joints.tilt) * Translation(0.0, g.H, 0.0);
  f.X_WL = f.X_WC * Translation(g.B, 0.0, 0.0) * RotY(joints.left);    // eq. 5
  f.X_WR = f.X_WC * Translation(-g.B, 0.0, 0.0) * RotY(joints.right);  // eq. 6
  f.X_WCamLeft = f.X_WL * EyeToCamera(g.delta_l);                      // eq. 7
  f.X_WCamRight = f.X_WR * EyeToCamera(g.delta_r);                     // eq. 8
  if (const auto p_c = FixationInCyclopean(g, joints.left, joints.right)) {
    f.p_WFixation = f.X_WC * *p_c;  // eq. 9 when left = -right
  }
  return f;
}

Eigen::Vector2d AxisErrors(const HeadDescription& head, const PopeyeJoints& joints,
                           const Eigen::Vector3d& p_W) {
  const HeadFrames f = ForwardKinematics(head, joints);
  Eigen::Vector2d errors;
  for (int eye = 0; eye < 2; ++eye) {
    const Pose& X = eye == 0 ? f.X_WCamLeft : f.X_WCamRight;
    const Vector3d axis = X.linear().col(2);
    const Vector3d to_target = p_W - X.translation();
    errors[eye] = std::atan2(axis.cross(to_target).norm(), axis.dot(to_target));
  }
  return errors;
}

const char* ToString(Reachability reachability) {
  switch (reachability) {
    case Reachability::kReachable:
      return "reachable";
    case Reachability::kBehind:
      return "behind";
    case Reachability::kTooClose:
      return "too close";
    case Reachability::kJointLimit:
      return "joint limit";
    case Reachability::kDegenerate:
      return "degenerate";
    case Reachability::kNotConverged:
      return "not converged";
  }
  return "unknown";
}

IkResult SolveFixationClosedForm(const HeadDescription& head, const Eigen::Vector3d& p_W) {
  CheckTarget("SolveFixationClosedForm", p_W);
  const HeadGeometry& g = head.geometry();
  if (g.D != 0.0 || g.H != 0.0) {
    throw InvalidArgument(fmt::format(
        "SolveFixationClosedForm: eqs. 10-13 need D = H = 0, got D = {} m, H = {} m; use "
        "SolveFixation",
        g.D, g.H));
  }
  // The target in the paper's base frame {b} (x left, y up, z forward).
  const Vector3d p_b = PaperBase(head).inverse() * p_W;
  const double xb = p_b.x();
  const double yb = p_b.y();
  const double zb = p_b.z();
  const double rho = std::sqrt(xb * xb + zb * zb);
  PopeyeJoints q;
  // Eq. 12: tan(pan) = xb / zb; atan2 keeps the quadrant, so a target behind needs |pan| > 90.
  q.pan = rho > 0.0 ? std::atan2(xb, zb) : 0.0;
  // Eq. 13: tan(tilt) = -yb / sqrt(xb^2 + zb^2).
  q.tilt = std::atan2(-yb, rho);
  // Eq. 11: tan(right) = B cos(tilt) / sqrt(xb^2 + zb^2); on the pan axis (rho = 0) its limit,
  // B / |p_b|, since sqrt(xb^2 + zb^2) = |p_b| cos(tilt).
  q.right = rho > 0.0 ? std::atan(g.B * std::cos(q.tilt) / rho) : std::atan2(g.B, p_b.norm());
  q.left = -q.right;
  const bool degenerate = p_b.norm() < kDegenerateDistance;
  const std::string note =
      degenerate ? "the target is at the cyclopean point: pan, tilt and vergence are undefined; "
                 : "";
  return Finish(head, p_W, q, VergenceMode::kSymmetric, degenerate, false, note);
}

IkResult SolveFixation(const HeadDescription& head, const Eigen::Vector3d& p_W,
                       const IkOptions& options) {
  CheckTarget("SolveFixation", p_W);
  if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance) ||
      options.max_iterations < 1) {
    throw InvalidArgument(fmt::format(
        "SolveFixation: options need tolerance > 0 and max_iterations >= 1, got {} and {}",
        options.tolerance, options.max_iterations));
  }
  for (const Joint joint : kAllJoints) {
    if (!std::isfinite(options.seed[joint])) {
      throw InvalidArgument(fmt::format("SolveFixation: seed.{} must be finite, got {}",
                                        JointName(joint), options.seed[joint]));
    }
  }
  const Vector3d p_b = PaperBase(head).inverse() * p_W;
  const Geometric geometric = SolveGeometrically(head, p_b, options);
  PopeyeJoints wanted = geometric.joints;
  int iterations = 0;
  if (geometric.exact) {
    // Newton from the seed; if it lands on another branch (or fails), again from the
    // geometric solution, where it only polishes.
    PopeyeJoints seed = options.seed;
    if (options.mode == VergenceMode::kIndependent) seed.pan = geometric.joints.pan;
    NewtonOutcome newton = Newton(head, p_W, seed, options);
    iterations = newton.iterations;
    if (!newton.converged || !SameBranch(newton.joints, geometric.joints)) {
      newton = Newton(head, p_W, geometric.joints, options);
      iterations += newton.iterations;
    }
    if (newton.converged && SameBranch(newton.joints, geometric.joints)) wanted = newton.joints;
  }
  // In kIndependent the pan is the seed's: solved at its clamped value, reported if clamped.
  if (options.mode == VergenceMode::kIndependent) wanted.pan = options.seed.pan;
  IkResult result = Finish(head, p_W, wanted, options.mode, geometric.degenerate,
                           geometric.too_close, geometric.note);
  result.iterations = iterations;
  return result;
}

}  // namespace saccade::head
