#include "saccade/head/fixation.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "saccade/core/error.h"
#include "saccade/core/units.h"

namespace saccade::head {

using Eigen::Vector3d;
using Eigen::VectorXd;
using geometry::Pose;

namespace {

// |r|^2 below this is a fixation: |u - e_z| ~ 1e-13, an axis error of ~1e-13 rad, four orders
// below the 1e-9 rad the result promises.
constexpr double kConvergedMerit = 1e-26;
// The rule's optimum is reached when a step moves no joint by more than this (rad or m).
constexpr double kStepTolerance = 1e-9;
// The damping of the normal equations relative to the largest singular value: directions
// with singular values below ~1e-7 of it are rank deficiency (a humanoid's two vertical
// residuals are one condition at a fixation), not directions to step along.
constexpr double kDamping = 1e-7;
constexpr double kTinyTrace = 1e-300;
// A target this close to an optical centre has no direction.
constexpr double kOnCentre = 1e-9;
// A parameter this close to its limit counts as at it, for the active set.
constexpr double kAtLimit = 1e-14;
// Line search: sufficient decrease (Armijo) and the number of halvings.
constexpr double kArmijo = 1e-4;
constexpr int kHalvings = 40;
// Gauss-Newton steps that bring a step of the rule back onto the fixation (quadratic
// convergence: two or three suffice).
constexpr int kProjectionSteps = 8;

// The residual's Jacobian: 6 rows, one column per free parameter (a head with more than 16
// free joints would need a bigger bound).
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 16>;
using MatrixXX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 16, 16>;

constexpr double kUnreached = std::numeric_limits<double>::infinity();

std::string LimitText(double value, double lower, double upper, bool angular) {
  const double s = angular ? kRadToDeg : 1.0;
  const char* unit = angular ? " deg" : " m";
  return fmt::format("{:.3f}{} (its range is [{:.3f}, {:.3f}]{})", value * s, unit, lower * s,
                     upper * s, unit);
}

}  // namespace

struct FixationSolver::Impl {
  explicit Impl(const HeadModel& model);

  // The free parameters: a driven, unheld joint, or the first of a symmetric pair.
  struct Parameter {
    int joint = 0;
    int partner = -1;  // the pair's second joint, q[partner] = sign * x
    double sign = 0.0;
    double lower = -kUnreached;
    double upper = kUnreached;
    double sqrt_weight = 1.0;
    double preferred = 0.0;
  };

  Eigen::VectorXd Posture(const VectorXd& x) const {
    VectorXd q = q_base;
    for (int k = 0; k < m(); ++k) {
      q[parameters[k].joint] = x[k];
      if (parameters[k].partner >= 0) q[parameters[k].partner] = parameters[k].sign * x[k];
    }
    return q;
  }
  int m() const { return static_cast<int>(parameters.size()); }

  double Evaluate(const VectorXd& x, bool mid_axis, bool jacobian);
  void Directions(const VectorXd& x, VectorXd* range, VectorXd* null);
  double MaxStep(const VectorXd& x, const VectorXd& direction) const;
  VectorXd Clamped(VectorXd x) const;
  double Cost(const VectorXd& x) const;
  bool Fixate(VectorXd* x, bool mid_axis, int max_iterations, int* iterations, double* merit);
  bool Converge(VectorXd* x, bool mid_axis, int max_iterations, int* iterations, double* merit);
  FixationResult Classify(const VectorXd& x, double merit, const Vector3d& p_W) const;

  const HeadModel& head;
  const KinematicTree& tree;
  bool can_verge = true;
  std::vector<Parameter> parameters;

  // Per solve and per evaluation.
  Vector3d target = Vector3d::Zero();
  VectorXd q_base;
  std::vector<Pose> X_WL;
  Eigen::Matrix<double, 6, Eigen::Dynamic> J6;
  Eigen::Matrix<double, 6, 1> r;
  Matrix6X A;  // dr / dy, y = sqrt(W) x
  std::vector<bool> frozen;
  Matrix6X A_free;
  VectorXd pull, dx_range, dx_null, trial;
  MatrixXX normal;
  VectorXd rhs;
  Eigen::LDLT<MatrixXX> ldlt;
};

FixationSolver::Impl::Impl(const HeadModel& model) : head(model), tree(model.tree()) {
  const FixationRule& rule = head.fixation_rule();
  const int n = head.num_joints();
  std::vector<int> partner_of(n, -1);
  std::vector<double> sign_of(n, 0.0);
  std::vector<bool> dependent(n, false);
  for (const FixationRule::Pair& pair : rule.symmetric) {
    if (rule.hold[pair.a] || rule.hold[pair.b]) continue;
    partner_of[pair.a] = pair.b;
    sign_of[pair.a] = pair.sign;
    dependent[pair.b] = true;
  }
  for (int i = 0; i < n; ++i) {
    if (rule.hold[i] || !head.joint(i).driven || dependent[i]) continue;
    Parameter p;
    p.joint = i;
    p.lower = head.joint(i).limits.min;
    p.upper = head.joint(i).limits.max;
    double weight = rule.weights[i];
    double moment = rule.weights[i] * rule.preferred[i];
    if (partner_of[i] >= 0) {
      const int b = partner_of[i];
      p.partner = b;
      p.sign = sign_of[i];
      double lower = head.joint(b).limits.min / p.sign;
      double upper = head.joint(b).limits.max / p.sign;
      if (lower > upper) std::swap(lower, upper);
      p.lower = std::max(p.lower, lower);
      p.upper = std::min(p.upper, upper);
      // w_a (x - p_a)^2 + w_b (s x - p_b)^2 = (w_a + w_b s^2) (x - x_p)^2 + const.
      weight += rule.weights[b] * p.sign * p.sign;
      moment += rule.weights[b] * p.sign * rule.preferred[b];
    }
    p.sqrt_weight = std::sqrt(weight);
    p.preferred = std::clamp(moment / weight, p.lower, p.upper);
    parameters.push_back(p);
  }
  // A joint that moves one camera and not the other makes the eyes verge.
  can_verge = false;
  const int left = head.camera(0).link;
  const int right = head.camera(1).link;
  for (int j = 0; j < tree.num_joints(); ++j) {
    if (tree.joint(j).moves() && tree.Moves(j, left) != tree.Moves(j, right)) can_verge = true;
  }
  frozen.assign(m(), false);
  if (m() > Matrix6X::MaxColsAtCompileTime) {
    throw InvalidArgument(fmt::format("FixationSolver: head {} has {} free joints; at most {}",
                                      head.name(), m(), Matrix6X::MaxColsAtCompileTime));
  }
}

// Fills r (and A when asked) at x; returns |r|^2, or +inf when the target sits on an optical
// centre.
double FixationSolver::Impl::Evaluate(const VectorXd& x, bool mid_axis, bool jacobian) {
  const VectorXd q = Posture(x);
  head.ForwardKinematics(q, &X_WL);
  r.setZero();
  if (jacobian) A.setZero(6, m());
  const int views = mid_axis ? 1 : 2;
  for (int v = 0; v < views; ++v) {
    Pose X_WC = head.CameraPose(v, X_WL);
    if (mid_axis) {
      const Pose right = head.CameraPose(1, X_WL);
      const Eigen::Quaterniond a(X_WC.linear());
      const Eigen::Quaterniond b(right.linear());
      X_WC.linear() = a.slerp(0.5, b).toRotationMatrix();
      X_WC.translation() = 0.5 * (X_WC.translation() + right.translation());
    }
    const Vector3d d = target - X_WC.translation();
    const double distance = d.norm();
    if (!(distance > kOnCentre)) return kUnreached;
    const Vector3d u = X_WC.linear().transpose() * d / distance;
    r.segment<3>(3 * v) = u - Vector3d::UnitZ();
    if (!jacobian) continue;
    // dp_C/dq = -R^T (w x d + v_o) for the camera's angular velocity w and its centre's v_o;
    // du = (I - u u^T) / |d| dp_C. The mid-axis moves as either camera (they are rigid).
    tree.Jacobian(X_WL, head.camera(v).link, X_WC.translation(), &J6);
    const Eigen::Matrix3d P =
        (Eigen::Matrix3d::Identity() - u * u.transpose()) * X_WC.linear().transpose() / distance;
    for (int k = 0; k < m(); ++k) {
      const Parameter& p = parameters[k];
      Eigen::Matrix<double, 6, 1> column = J6.col(p.joint);
      if (p.partner >= 0) column += p.sign * J6.col(p.partner);
      const Vector3d w = column.head<3>();
      const Vector3d velocity = column.tail<3>();
      A.block<3, 1>(3 * v, k) = -P * (w.cross(d) + velocity) / p.sqrt_weight;
    }
  }
  return r.squaredNorm();
}

// The two directions at x (after Evaluate with the Jacobian): the minimum-norm Gauss-Newton
// correction of the fixation, and the step to the rule's optimum among the postures that keep
// it to first order, both in joint units. A parameter at a limit that a direction pushes
// outwards is frozen and the directions computed again without it.
void FixationSolver::Impl::Directions(const VectorXd& x, VectorXd* range, VectorXd* null) {
  std::fill(frozen.begin(), frozen.end(), false);
  range->resize(m());
  null->resize(m());
  for (int pass = 0; pass <= m(); ++pass) {
    A_free = A;
    pull.resize(m());
    for (int k = 0; k < m(); ++k) {
      const Parameter& p = parameters[k];
      pull[k] = frozen[k] ? 0.0 : p.sqrt_weight * (p.preferred - x[k]);
      if (frozen[k]) A_free.col(k).setZero();
    }
    // Damped normal equations, N = A^T A + l^2 I: the range step -N^-1 A^T r is the
    // minimum-norm Gauss-Newton step, and I - N^-1 A^T A = l^2 N^-1 projects on A's null
    // space (directions with singular values well below l count as null). An m x m LDLT is
    // ten times cheaper than an SVD of A, and the solve runs it a few dozen times.
    normal.noalias() = A_free.transpose() * A_free;
    const double damping = kDamping * kDamping * std::max(normal.trace(), kTinyTrace);
    normal.diagonal().array() += damping;
    ldlt.compute(normal);
    rhs.noalias() = -A_free.transpose() * r;
    const VectorXd dy_range = ldlt.solve(rhs);
    const VectorXd dy_null = damping * ldlt.solve(pull);
    bool newly_frozen = false;
    for (int k = 0; k < m(); ++k) {
      const Parameter& p = parameters[k];
      (*range)[k] = frozen[k] ? 0.0 : dy_range[k] / p.sqrt_weight;
      (*null)[k] = frozen[k] ? 0.0 : dy_null[k] / p.sqrt_weight;
      const double d = (*range)[k] + (*null)[k];
      const bool outwards =
          (x[k] <= p.lower + kAtLimit && d < 0.0) || (x[k] >= p.upper - kAtLimit && d > 0.0);
      if (!frozen[k] && outwards) newly_frozen = frozen[k] = true;
    }
    if (!newly_frozen) return;
  }
}

// The largest step <= 1 along `direction` that stays within the limits.
double FixationSolver::Impl::MaxStep(const VectorXd& x, const VectorXd& direction) const {
  double alpha = 1.0;
  for (int k = 0; k < m(); ++k) {
    const double d = direction[k];
    if (d > 0.0) alpha = std::min(alpha, (parameters[k].upper - x[k]) / d);
    if (d < 0.0) alpha = std::min(alpha, (parameters[k].lower - x[k]) / d);
  }
  return std::max(alpha, 0.0);
}

VectorXd FixationSolver::Impl::Clamped(VectorXd x) const {
  for (int k = 0; k < m(); ++k) x[k] = std::clamp(x[k], parameters[k].lower, parameters[k].upper);
  return x;
}

// The rule's cost, sum w (x - x_preferred)^2.
double FixationSolver::Impl::Cost(const VectorXd& x) const {
  double cost = 0.0;
  for (int k = 0; k < m(); ++k) {
    const double d = parameters[k].sqrt_weight * (x[k] - parameters[k].preferred);
    cost += d * d;
  }
  return cost;
}

// Gauss-Newton on the fixation alone, with a backtracking line search on |r|^2, until it holds
// (true) or no step lowers the residual (false).
bool FixationSolver::Impl::Fixate(VectorXd* x, bool mid_axis, int max_iterations, int* iterations,
                                  double* merit) {
  // r and A always belong to *x when a step starts: a trial's evaluation is the next step's.
  *merit = Evaluate(*x, mid_axis, true);
  for (int i = 0; i < max_iterations; ++i) {
    if (*merit < kConvergedMerit) return true;
    if (!std::isfinite(*merit)) return false;
    ++*iterations;
    Directions(*x, &dx_range, &dx_null);
    bool stepped = false;
    for (double alpha = MaxStep(*x, dx_range), h = 0; h < kHalvings && alpha > 0.0;
         ++h, alpha *= 0.5) {
      trial = Clamped(*x + alpha * dx_range);
      const double trial_merit = Evaluate(trial, mid_axis, true);
      if (trial_merit < *merit * (1.0 - kArmijo * alpha)) {
        *x = trial;
        *merit = trial_merit;
        stepped = true;
        break;
      }
    }
    if (!stepped) {
      *merit = Evaluate(*x, mid_axis, true);
      break;
    }
  }
  return *merit < kConvergedMerit;
}

// Fixates from x, then walks to the rule's optimum along the postures that fixate: each step
// goes along the rule's direction and back onto the fixation with Fixate, and is kept when the
// rule's cost went down (halved otherwise).
bool FixationSolver::Impl::Converge(VectorXd* x, bool mid_axis, int max_iterations, int* iterations,
                                    double* merit) {
  if (!Fixate(x, mid_axis, max_iterations, iterations, merit)) return false;
  for (int outer = 0; outer < max_iterations; ++outer) {
    Directions(*x, &dx_range, &dx_null);  // r and A are at *x (Fixate's last evaluation)
    if (dx_null.lpNorm<Eigen::Infinity>() < kStepTolerance) break;
    const double cost = Cost(*x);
    const VectorXd direction = dx_null;
    bool stepped = false;
    for (double alpha = MaxStep(*x, direction), h = 0; h < kHalvings && alpha > 0.0;
         ++h, alpha *= 0.5) {
      VectorXd moved = Clamped(*x + alpha * direction);
      double moved_merit = kUnreached;
      if (Fixate(&moved, mid_axis, kProjectionSteps, iterations, &moved_merit) &&
          Cost(moved) < cost) {
        *x = moved;
        *merit = moved_merit;
        stepped = true;
        break;
      }
    }
    if (!stepped) break;
  }
  *merit = Evaluate(*x, mid_axis, false);
  return *merit < kConvergedMerit;
}

FixationResult FixationSolver::Impl::Classify(const VectorXd& x, double merit,
                                              const Vector3d& p_W) const {
  FixationResult result;
  result.joints = Posture(x);
  if (!std::isfinite(merit)) {
    result.reachability = Reachability::kDegenerate;
    result.message = fmt::format(
        "the target ({:.4f}, {:.4f}, {:.4f}) sits on an optical centre: it has no direction",
        p_W.x(), p_W.y(), p_W.z());
    return result;
  }
  const Vector3d p_B = head.X_WB().inverse() * p_W;
  std::string at_limit;
  for (int k = 0; k < m(); ++k) {
    const Parameter& p = parameters[k];
    if (x[k] > p.lower + kAtLimit && x[k] < p.upper - kAtLimit) continue;
    const bool angular = tree.joint(tree.variable_joint(p.joint)).type != JointType::kPrismatic;
    at_limit = fmt::format("joint {} would leave its limits: it stops at {}",
                           head.joint_name(p.joint), LimitText(x[k], p.lower, p.upper, angular));
    break;
  }
  if (p_B.x() <= 0.0) {
    result.reachability = Reachability::kBehind;
    result.message =
        fmt::format("the target is behind the head ({:.3f} m along its forward axis)", p_B.x());
    if (!at_limit.empty()) result.message += "; " + at_limit;
  } else if (!at_limit.empty()) {
    result.reachability = Reachability::kJointLimit;
    const double baseline =
        (head.CameraPose(0, X_WL).translation() - head.CameraPose(1, X_WL).translation()).norm();
    if (p_B.norm() < 4.0 * baseline) result.reachability = Reachability::kTooClose;
    result.message =
        (result.reachability == Reachability::kTooClose
             ? fmt::format("the target is too close ({:.3f} m from the head's base): ", p_B.norm())
             : std::string()) +
        at_limit;
  } else {
    result.reachability = Reachability::kNotConverged;
    result.message = "no posture within the limits puts both optical axes through the target";
  }
  return result;
}

FixationSolver::FixationSolver(const HeadModel& head) : impl_(std::make_unique<Impl>(head)) {}
FixationSolver::~FixationSolver() = default;

bool FixationSolver::can_verge() const { return impl_->can_verge; }

FixationResult FixationSolver::Solve(const Vector3d& p_W, const FixationOptions& options) {
  Impl& s = *impl_;
  if (!p_W.allFinite()) {
    throw InvalidArgument(
        fmt::format("SolveFixation: the target p_W must be finite, got ({}, {}, {})", p_W.x(),
                    p_W.y(), p_W.z()));
  }
  const HeadModel& head = s.head;
  const VectorXd home = head.HomePosture();
  const VectorXd seed = options.seed.size() == 0 ? home : options.seed;
  if (seed.size() != head.num_joints() || !seed.allFinite()) {
    throw InvalidArgument(
        fmt::format("SolveFixation: the seed must hold {} finite joint values, got {}",
                    head.num_joints(), seed.size()));
  }
  s.target = p_W;
  s.q_base = seed;
  for (int i = 0; i < head.num_joints(); ++i) {
    if (!head.joint(i).driven) s.q_base[i] = head.joint(i).hold;
    s.q_base[i] = std::clamp(s.q_base[i], head.joint(i).limits.min, head.joint(i).limits.max);
  }
  const auto parameters_of = [&s](const VectorXd& q) {
    VectorXd x(s.m());
    for (int k = 0; k < s.m(); ++k) {
      x[k] = std::clamp(q[s.parameters[k].joint], s.parameters[k].lower, s.parameters[k].upper);
    }
    return x;
  };
  const bool mid_axis = !s.can_verge;
  FixationResult result;
  int iterations = 0;
  VectorXd best;
  double best_merit = kUnreached;
  // Seeds in turn: the current posture, home, and home turned first with the mid-axis.
  for (int attempt = 0; attempt < 3; ++attempt) {
    VectorXd x = parameters_of(attempt == 0 ? s.q_base : home);
    double merit = kUnreached;
    if (attempt == 2 && !mid_axis)
      s.Converge(&x, true, options.max_iterations, &iterations, &merit);
    const bool converged = s.Converge(&x, mid_axis, options.max_iterations, &iterations, &merit);
    if (merit < best_merit || best.size() == 0) {
      best = x;
      best_merit = merit;
    }
    if (converged) break;
  }
  s.Evaluate(best, mid_axis, false);
  result = s.Classify(best, best_merit, p_W);
  result.iterations = iterations;
  result.mid_axis = mid_axis;
  // The promise, measured on the result: axes through the target within the tolerance.
  double error = 0.0;
  for (int v = 0; v < (mid_axis ? 1 : 2); ++v) {
    const Vector3d u = s.r.segment<3>(3 * v) + Vector3d::UnitZ();
    error = std::max(error, std::atan2(u.cross(Vector3d::UnitZ()).norm(), u.z()));
  }
  result.axis_error = std::isfinite(best_merit) ? error : M_PI;
  if (best_merit < kConvergedMerit && error <= options.axis_tolerance) {
    result.reachability = Reachability::kReachable;
    result.message.clear();
  }
  return result;
}

std::optional<Vector3d> FixationPoint(const Pose& X_WLeft, const Pose& X_WRight) {
  // o_l + s a_l and o_r + t a_r closest: the normal equations of |o_l + s a_l - o_r - t a_r|^2.
  const Vector3d a = X_WLeft.linear().col(2);
  const Vector3d b = X_WRight.linear().col(2);
  const Vector3d w = X_WLeft.translation() - X_WRight.translation();
  const double ab = a.dot(b);
  const double denominator = 1.0 - ab * ab;  // sin^2 of the angle between the axes
  if (!(denominator > 1e-24)) return std::nullopt;
  const double s = (ab * b.dot(w) - a.dot(w)) / denominator;
  const double t = (b.dot(w) - ab * a.dot(w)) / denominator;
  if (!(s > 0.0) || !(t > 0.0)) return std::nullopt;
  return 0.5 * (X_WLeft.translation() + s * a + X_WRight.translation() + t * b);
}

FixationResult SolveFixation(const HeadModel& head, const Vector3d& p_W,
                             const FixationOptions& options) {
  FixationSolver solver(head);
  return solver.Solve(p_W, options);
}

Eigen::Vector2d AxisErrors(const HeadModel& head, const Eigen::Ref<const VectorXd>& q,
                           const Vector3d& p_W) {
  std::vector<Pose> X_WL;
  head.ForwardKinematics(q, &X_WL);
  Eigen::Vector2d errors;
  for (int eye = 0; eye < 2; ++eye) {
    const Pose X_WC = head.CameraPose(eye, X_WL);
    const Vector3d axis = X_WC.linear().col(2);
    const Vector3d t = p_W - X_WC.translation();
    errors[eye] = std::atan2(axis.cross(t).norm(), axis.dot(t));
  }
  return errors;
}

}  // namespace saccade::head
