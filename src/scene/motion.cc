// Scripted motion: poses as pure functions of time (no state, so the same t always gives
// the same bits).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace saccade::scene {
namespace {

// A rotation must be orthonormal to this to be a pose (rpy-built ones are, to ~1e-16).
constexpr double kRotationTolerance = 1e-9;

bool IsRigid(const geometry::Pose& X) {
  const Eigen::Matrix3d R = X.linear();
  return X.matrix().allFinite() &&
         (R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), kRotationTolerance) &&
         std::abs(R.determinant() - 1.0) <= kRotationTolerance;
}

}  // namespace

Motion Motion::Static(const geometry::Pose& X_WO) {
  if (!IsRigid(X_WO))
    throw InvalidArgument("Motion::Static: X_WO must be a finite rigid transform");
  Motion motion;
  motion.kind_ = Kind::kStatic;
  motion.waypoints_ = {Waypoint{0.0, X_WO}};
  return motion;
}

Motion Motion::Waypoints(std::vector<Waypoint> waypoints, bool loop) {
  if (waypoints.empty()) throw InvalidArgument("Motion::Waypoints: needs at least one waypoint");
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const double t = waypoints[i].time;
    if (!std::isfinite(t)) {
      throw InvalidArgument(
          fmt::format("Motion::Waypoints: waypoint {} has time {}, expected a "
                      "finite number of seconds",
                      i, t));
    }
    if (i > 0 && !(t > waypoints[i - 1].time)) {
      throw InvalidArgument(fmt::format(
          "Motion::Waypoints: times must increase strictly, got {} s after {} s (waypoint {})", t,
          waypoints[i - 1].time, i));
    }
    if (!IsRigid(waypoints[i].pose)) {
      throw InvalidArgument(
          fmt::format("Motion::Waypoints: waypoint {} is not a finite rigid transform", i));
    }
  }
  if (loop && !(waypoints.back().time > 0.0)) {
    throw InvalidArgument(fmt::format(
        "Motion::Waypoints: a loop needs the last waypoint's time (its period) > 0, got {} s",
        waypoints.back().time));
  }
  Motion motion;
  motion.kind_ = Kind::kWaypoints;
  motion.waypoints_ = std::move(waypoints);
  motion.loop_ = loop;
  return motion;
}

Motion Motion::ConstantVelocity(const geometry::Pose& X_WO_at_0, const Eigen::Vector3d& v_W,
                                const Eigen::Vector3d& w_W) {
  if (!IsRigid(X_WO_at_0)) {
    throw InvalidArgument("Motion::ConstantVelocity: X_WO(0) must be a finite rigid transform");
  }
  if (!v_W.allFinite() || !w_W.allFinite()) {
    throw InvalidArgument("Motion::ConstantVelocity: velocities must be finite");
  }
  Motion motion;
  motion.kind_ = Kind::kConstantVelocity;
  motion.waypoints_ = {Waypoint{0.0, X_WO_at_0}};
  motion.v_W_ = v_W;
  motion.w_W_ = w_W;
  return motion;
}

geometry::Pose Motion::PoseAt(double t) const {
  // Not a time: the pose at time 0 (never throws).
  if (!std::isfinite(t)) t = 0.0;
  switch (kind_) {
    case Kind::kStatic:
      return waypoints_.front().pose;
    case Kind::kConstantVelocity: {
      const geometry::Pose& X0 = waypoints_.front().pose;
      geometry::Pose X = geometry::Pose::Identity();
      const double speed = w_W_.norm();
      X.linear() = speed > 0.0
                       ? Eigen::Matrix3d(Eigen::AngleAxisd(speed * t, w_W_ / speed) * X0.linear())
                       : X0.linear();
      X.translation() = X0.translation() + v_W_ * t;
      return X;
    }
    case Kind::kWaypoints:
      break;
  }
  if (loop_) {
    // Wrap into [0, period): the pose goes back to the start of the script each period.
    const double period = waypoints_.back().time;
    t = std::fmod(t, period);
    if (t < 0.0) t += period;
    if (t >= period) t = 0.0;  // rounding of t + period
  }
  if (t <= waypoints_.front().time) return waypoints_.front().pose;
  if (t >= waypoints_.back().time) return waypoints_.back().pose;
  // The segment [a, b] with a.time <= t < b.time.
  const auto after =
      std::upper_bound(waypoints_.begin(), waypoints_.end(), t,
                       [](double time, const Waypoint& waypoint) { return time < waypoint.time; });
  const Waypoint& b = *after;
  const Waypoint& a = *(after - 1);
  if (t == a.time) return a.pose;
  const double s = (t - a.time) / (b.time - a.time);
  const Eigen::Quaterniond qa(a.pose.linear());
  const Eigen::Quaterniond qb(b.pose.linear());
  geometry::Pose X = geometry::Pose::Identity();
  X.linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  X.translation() = a.pose.translation() + s * (b.pose.translation() - a.pose.translation());
  return X;
}

}  // namespace saccade::scene
