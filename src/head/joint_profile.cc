#include "saccade/head/joint_profile.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "saccade/core/error.h"

namespace saccade::head {
namespace {

// The classical time-optimal rest-to-rest motion, solved in the frame of the target: from
// relative position e0 and velocity w0 to (0, 0) with |acceleration| <= a and relative
// velocity in [-vlim_neg, vlim_pos]. Phases: t1 at a1, tc at 0, t3 at -a1 (sign s of a1).
struct Bang {
  bool feasible = true;
  double t1 = 0.0;
  double a1 = 0.0;
  double tc = 0.0;
  double t3 = 0.0;
  double total() const { return t1 + tc + t3; }
};

Bang SolveRelative(double e0, double w0, double a, double vlim_pos, double vlim_neg) {
  Bang bang;
  const double d = -e0;                             // distance to go
  const double stop = w0 * std::abs(w0) / (2 * a);  // where full braking stops, from here
  const double r = d - stop;
  if (r == 0.0) {  // braking at the limit lands exactly on the target (or already there)
    bang.t3 = std::abs(w0) / a;
    bang.a1 = w0 > 0 ? a : -a;  // phase 3 applies -a1, i.e. brakes against w0
    return bang;
  }
  const double s = r > 0 ? 1.0 : -1.0;
  const double u0 = s * w0;  // start velocity along the direction of motion
  const double D = s * d;
  const double vlim = s > 0 ? vlim_pos : vlim_neg;
  bang.a1 = s * a;
  // Triangle: the peak vp covers D in (vp^2 - u0^2)/(2a) + vp^2/(2a).
  const double vp = std::sqrt(std::max(0.0, a * D + 0.5 * u0 * u0));
  if (vp <= vlim) {
    bang.t1 = std::max(0.0, (vp - u0) / a);
    bang.t3 = vp / a;
    return bang;
  }
  if (vlim <= 0.0) {  // the target runs away at the velocity limit: never caught
    bang.feasible = false;
    return bang;
  }
  // Trapezoid: cruise at vlim for what the two ramps leave of D.
  bang.t1 = std::max(0.0, (vlim - u0) / a);
  bang.t3 = vlim / a;
  const double ramps = (vlim * vlim - u0 * u0) / (2 * a) + vlim * vlim / (2 * a);
  bang.tc = std::max(0.0, (D - ramps) / vlim);
  return bang;
}

}  // namespace

JointProfile::JointProfile(double position)
    : min_(-std::numeric_limits<double>::infinity()),
      max_(std::numeric_limits<double>::infinity()),
      start_x_(position),
      tail_x_(position),
      target_x_(position) {}

void JointProfile::Add(double duration, double a) {
  if (!(duration > 0.0)) return;
  SACCADE_ASSERT(count_ < kMaxSegments, "JointProfile: too many segments");
  Segment segment;
  segment.t0 = end_time_;
  if (count_ == 0) {
    segment.x0 = start_x_;
    segment.v0 = start_v_;
  } else {
    const Segment& last = segments_[count_ - 1];
    const double tau = end_time_ - last.t0;
    segment.x0 = last.x0 + last.v0 * tau + 0.5 * last.a * tau * tau;
    segment.v0 = last.v0 + last.a * tau;
  }
  segment.a = a;
  segments_[count_++] = segment;
  end_time_ += duration;
}

bool JointProfile::WithinRange() const {
  for (int i = 0; i < count_; ++i) {
    const Segment& s = segments_[i];
    const double tau = (i + 1 < count_ ? segments_[i + 1].t0 : end_time_) - s.t0;
    const double v1 = s.v0 + s.a * tau;
    double lo = std::min(s.x0, s.x0 + s.v0 * tau + 0.5 * s.a * tau * tau);
    double hi = std::max(s.x0, s.x0 + s.v0 * tau + 0.5 * s.a * tau * tau);
    if (s.a != 0.0 && (s.v0 > 0) != (v1 > 0)) {  // turns inside the segment
      const double turn = s.x0 - s.v0 * s.v0 / (2 * s.a);
      lo = std::min(lo, turn);
      hi = std::max(hi, turn);
    }
    // Rounding slack only: Position() clamps the last ulps anyway.
    const double slack = 1e-12 * (1.0 + std::abs(min_) + std::abs(max_));
    if (lo < min_ - slack || hi > max_ + slack) return false;
  }
  return true;
}

JointProfile JointProfile::Plan(const JointLimits& limits, double x0, double v0, double target,
                                double target_velocity) {
  const double a = limits.max_acceleration;
  const double vmax = limits.max_velocity;
  SACCADE_ASSERT(std::isfinite(x0) && std::isfinite(v0) && std::isfinite(target) &&
                     std::isfinite(target_velocity),
                 "JointProfile::Plan: non-finite input");
  SACCADE_ASSERT(
      limits.min < limits.max && vmax > 0 && a > 0 && std::isfinite(vmax) && std::isfinite(a),
      "JointProfile::Plan: invalid limits");
  SACCADE_ASSERT(limits.Contains(target) && std::abs(target_velocity) <= vmax,
                 "JointProfile::Plan: target outside the limits");

  JointProfile p(target);
  p.min_ = limits.min;
  p.max_ = limits.max;
  p.start_x_ = x0;
  p.start_v_ = v0;
  p.target_v_ = target_velocity;

  // Saccade to a fixed point (also the fallback of a pursuit: the limit it heads to).
  auto saccade = [&](double goal) {
    p.count_ = 0;
    p.end_time_ = 0.0;
    const Bang bang = SolveRelative(x0 - goal, v0, a, vmax, vmax);
    SACCADE_ASSERT(bang.feasible, "JointProfile::Plan: saccade infeasible");
    p.Add(bang.t1, bang.a1);
    p.Add(bang.tc, 0.0);
    p.Add(bang.t3, -bang.a1);
    p.tail_x_ = goal;
    p.duration_ = p.end_time_;
  };

  if (target_velocity == 0.0) {
    saccade(target);
    p.target_stop_t_ = 0.0;
    return p;
  }

  // Pursuit. The target heads to `limit`; the joint must start braking when the target
  // passes `brake_x` (at t_brake) to stop on the limit: v_t^2 / (2a) before it.
  const double vt = target_velocity;
  const double sv = vt > 0 ? 1.0 : -1.0;
  const double limit = vt > 0 ? limits.max : limits.min;
  const double brake_x = limit - sv * vt * vt / (2 * a);
  const double t_brake = (brake_x - target) / vt;
  p.target_stop_t_ = std::max(0.0, (limit - target) / vt);

  auto go_to_limit = [&] {
    saccade(limit);
    p.cut_at_limit_ = true;
  };
  if (!(t_brake > 0.0)) {
    go_to_limit();
    return p;
  }
  const Bang bang = SolveRelative(x0 - target, v0 - vt, a, vmax - vt, vmax + vt);
  if (!bang.feasible || bang.total() > t_brake) {
    go_to_limit();
    return p;
  }
  // Relative and absolute accelerations are equal: the target's velocity is constant.
  p.Add(bang.t1, bang.a1);
  p.Add(bang.tc, 0.0);
  p.Add(bang.t3, -bang.a1);
  if (!p.WithinRange()) {
    go_to_limit();
    return p;
  }
  const double t_meet = p.end_time_;
  p.duration_ = t_meet;
  // Track: start exactly on the target (no accumulated rounding), then brake onto the limit.
  if (t_brake > t_meet) {
    p.Add(t_brake - t_meet, 0.0);
    p.segments_[p.count_ - 1].x0 = target + vt * t_meet;
    p.segments_[p.count_ - 1].v0 = vt;
  }
  p.Add(std::abs(vt) / a, -sv * a);
  p.segments_[p.count_ - 1].x0 = target + vt * std::max(t_brake, t_meet);
  p.segments_[p.count_ - 1].v0 = vt;
  p.tail_x_ = limit;
  return p;
}

int JointProfile::SegmentAt(double t) const {
  if (t >= end_time_) return -1;
  int i = 0;
  while (i + 1 < count_ && segments_[i + 1].t0 <= t) ++i;
  return i;
}

double JointProfile::Position(double t) const {
  const int i = SegmentAt(t);
  if (i < 0) return tail_x_;
  const Segment& s = segments_[i];
  const double tau = std::max(0.0, t - s.t0);
  return std::clamp(s.x0 + s.v0 * tau + 0.5 * s.a * tau * tau, min_, max_);
}

double JointProfile::Velocity(double t) const {
  const int i = SegmentAt(t);
  if (i < 0) return 0.0;
  const Segment& s = segments_[i];
  return s.v0 + s.a * std::max(0.0, t - s.t0);
}

double JointProfile::Acceleration(double t) const {
  const int i = SegmentAt(t);
  return i < 0 ? 0.0 : segments_[i].a;
}

double JointProfile::TargetPosition(double t) const {
  if (target_v_ == 0.0 || t >= target_stop_t_) {
    return target_v_ == 0.0 ? target_x_ : (target_v_ > 0 ? max_ : min_);
  }
  return target_x_ + target_v_ * t;
}

double JointProfile::TargetVelocity(double t) const {
  return t >= target_stop_t_ ? 0.0 : target_v_;
}

}  // namespace saccade::head
