#include "saccade/mapping/inhibition_3d.h"

#include <algorithm>
#include <cmath>

#include "saccade/core/error.h"

namespace saccade::mapping {

bool Inhibition3d::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kTimeConstants.Contains(time_constant_s)) {
    what = kTimeConstants.Refusal("time_constant_s", time_constant_s);
  } else if (!kRadii.Contains(radius_m)) {
    what = kRadii.Refusal("radius_m", radius_m);
  } else if (!kForgetBelow.Contains(forget_below)) {
    what = kForgetBelow.Refusal("forget_below", forget_below);
  } else if (falloff != Falloff::kBall && falloff != Falloff::kGaussian) {
    what = "falloff " + std::to_string(static_cast<int>(falloff)) + ", expected kBall or kGaussian";
  }
  if (what.empty()) return true;
  if (error) *error = "Inhibition3d::Options: " + what;
  return false;
}

Inhibition3d::Inhibition3d() : Inhibition3d(Options()) {}

Inhibition3d::Inhibition3d(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

double Inhibition3d::forget_after_s() const {
  return options_.time_constant_s * std::log(1.0 / options_.forget_below);
}

double Inhibition3d::Level(const Place& place, double time_s) const {
  const double age_s = time_s - place.visit_time_s;
  if (!(age_s >= 0)) return 0.0;  // visited after time_s (or a NaN time)
  const double decay = std::exp(-age_s / options_.time_constant_s);
  return decay >= options_.forget_below ? decay : 0.0;
}

double Inhibition3d::Inhibition(const Eigen::Vector3d& p_W, double time_s) const {
  const double r2 = options_.radius_m * options_.radius_m;
  // Falloff::kGaussian: sigma = radius_m / 2, so d^2 / (2 sigma^2) = 2 d^2 / radius_m^2.
  const double gauss = 2.0 / r2;
  double best = 0.0;
  for (const Place& place : places_) {
    const double d2 = (p_W - place.p_W).squaredNorm();
    if (!(d2 <= r2)) continue;
    double level = Level(place, time_s);
    if (options_.falloff == Falloff::kGaussian) level *= std::exp(-gauss * d2);
    best = std::max(best, level);
  }
  return best;
}

void Inhibition3d::Advance(double time_s) {
  if (latest_time_s_ && time_s < *latest_time_s_) places_.clear();  // a new run
  latest_time_s_ = time_s;
  std::erase_if(places_, [&](const Place& place) { return Level(place, time_s) == 0.0; });
}

void Inhibition3d::Forget(double time_s) {
  if (!std::isfinite(time_s)) return;
  Advance(time_s);
}

void Inhibition3d::Reset() {
  places_.clear();
  latest_time_s_.reset();
}

bool Inhibition3d::Visit(const Eigen::Vector3d& p_W, double time_s) {
  return Record(p_W, time_s, std::nullopt, p_W);
}

bool Inhibition3d::Visit(const Eigen::Vector3d& p_W, double time_s, int object_id,
                         const Eigen::Isometry3d& X_WO) {
  if (!X_WO.matrix().allFinite()) return false;
  return Record(p_W, time_s, object_id, X_WO.inverse() * p_W);
}

bool Inhibition3d::Record(const Eigen::Vector3d& p_W, double time_s,
                          const std::optional<int>& object_id, const Eigen::Vector3d& p_O) {
  if (!p_W.allFinite() || !std::isfinite(time_s)) return false;
  Advance(time_s);
  // Renew the nearest live place of the same anchor within radius_m rather than stacking
  // places on one spot; it moves to the back, keeping places_ in order of visit.
  auto nearest = places_.end();
  double nearest_d = options_.radius_m;
  for (auto it = places_.begin(); it != places_.end(); ++it) {
    if (it->object_id != object_id) continue;
    const double d = (it->p_W - p_W).norm();
    if (d <= nearest_d) {
      nearest_d = d;
      nearest = it;
    }
  }
  if (nearest != places_.end()) places_.erase(nearest);
  places_.push_back(Place{p_W, time_s, object_id, p_O});
  return true;
}

void Inhibition3d::MoveObject(int object_id, const Eigen::Isometry3d& X_WO) {
  if (!X_WO.matrix().allFinite()) return;
  for (Place& place : places_) {
    if (place.object_id == object_id) place.p_W = X_WO * place.p_O;
  }
}

}  // namespace saccade::mapping
