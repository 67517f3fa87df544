#pragma once
// Inhibition of return in 3D: the places the head has looked at, anchored in the world (or on a
// moving object), each inhibiting a ball about it with a strength that decays with time, so
// that attention is kept away from what it has just seen and comes back to it later.
//
// A place visited at time t0 with centre c (world frame W, z up, metres) inhibits a point p at
// time t >= t0 by
//   I(p, t) = exp(-(t - t0) / time_constant_s) * f(|p - c|)
// where the falloff f is 1 inside the ball of radius_m (Falloff::kBall), or the Gaussian
// exp(-d^2 / (2 sigma^2)) with sigma = radius_m / 2 inside it (Falloff::kGaussian: 1 at the
// centre, exp(-2) = 0.14 at the edge); f = 0 beyond radius_m either way. The inhibition of a
// point is the largest over the places, in [0, 1]. A place whose decay exp(-(t - t0) / tau) has
// fallen below forget_below is forgotten: it inhibits nothing from then on, and Forget (or the
// next Visit) removes it, forget_after_s() = tau ln(1 / forget_below) after its visit (3 tau for
// the default 0.05).
//
// A place may be anchored to a moving object (an id of the caller's choosing): it is then kept
// in the object's frame O and moves with it when MoveObject gives the object's new pose X_WO.
//
// Time: seconds on one clock (e.g. the scene time). Visit and Forget take non-decreasing times;
// an earlier time than the latest they were given means a new run (a simulation reset) and
// clears every place first. Inhibition, which changes nothing, does not see places visited after
// the time it is asked about.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/interval.h"

namespace saccade::mapping {

/// World-anchored inhibition of return that decays with time. State, not thread-safe.
class Inhibition3d {
 public:
  /// How the inhibition falls off with the distance from a place's centre.
  enum class Falloff {
    kBall,      ///< the same everywhere within radius_m
    kGaussian,  ///< exp(-d^2 / (2 sigma^2)), sigma = radius_m / 2, within radius_m
  };

  struct Options {
    double time_constant_s = 5.0;  ///< decay time constant tau, s: kTimeConstants
    double radius_m = 0.15;        ///< radius of the inhibited ball about a place, m: kRadii
    double forget_below = 0.05;    ///< a place is forgotten below this decay: kForgetBelow
    Falloff falloff = Falloff::kBall;

    // The valid values, stated once (for IsValid and for a component's parameter ranges).
    static constexpr Interval kTimeConstants = Interval::LeftOpen(0, 1e9);
    static constexpr Interval kRadii = Interval::LeftOpen(0, 1e6);
    static constexpr Interval kForgetBelow = Interval{0.0, 1.0, true, true};

    /// Whether every field is in its range; if not, `error` (when not null) names the first
    /// field out of range, its value and the range expected.
    bool IsValid(std::string* error) const;
  };

  /// A visited place.
  struct Place {
    Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< centre now, world frame, m
    double visit_time_s = 0.0;                      ///< when it was (last) visited, s
    std::optional<int> object_id;                   ///< the object it moves with, if any
    Eigen::Vector3d p_O = Eigen::Vector3d::Zero();  ///< centre in that object's frame, m
  };

  Inhibition3d();  ///< default Options
  /// Throws InvalidArgument with IsValid's message.
  explicit Inhibition3d(const Options& options);

  /// Records a look at the world point p_W at time_s (a place fixed in the world). A live place
  /// within radius_m of p_W that is not anchored to an object is renewed instead (its centre
  /// moves to p_W, its visit time becomes time_s), so that dwelling on one spot keeps one place.
  /// Forgets faded places first. Returns false, changing nothing, when p_W or time_s is not
  /// finite (a per-frame path: never throws).
  bool Visit(const Eigen::Vector3d& p_W, double time_s);
  /// The same for a point on the object `object_id`, whose pose is X_WO at time_s: the place is
  /// kept in the object's frame and follows MoveObject. Renews a live place of the same object
  /// within radius_m. Returns false, changing nothing, when an input is not finite.
  bool Visit(const Eigen::Vector3d& p_W, double time_s, int object_id,
             const Eigen::Isometry3d& X_WO);

  /// The object `object_id` is now at X_WO: the places anchored to it move with it. Places of
  /// an object that is never moved again stay where it was last seen. A non-finite pose is
  /// ignored.
  void MoveObject(int object_id, const Eigen::Isometry3d& X_WO);

  /// Inhibition of the world point p_W at time_s, in [0, 1]: the largest over the places (see
  /// the file comment); 0 far from every place, and for a point no place reaches.
  double Inhibition(const Eigen::Vector3d& p_W, double time_s) const;

  /// The decay of one place at time_s, in [0, 1]: its inhibition at its centre (0 once
  /// forgotten or before its visit), e.g. for the opacity of a place drawn in a GUI.
  double Level(const Place& place, double time_s) const;

  /// Removes the places forgotten at time_s (an earlier time than the latest clears all).
  void Forget(double time_s);

  /// Forgets every place.
  void Reset();

  /// Seconds after its last visit that a place is forgotten: time_constant_s ln(1/forget_below).
  double forget_after_s() const;

  /// The places, oldest visit first; some may have faded since the last Visit or Forget.
  const std::vector<Place>& places() const { return places_; }
  const Options& options() const { return options_; }

 private:
  bool Record(const Eigen::Vector3d& p_W, double time_s, const std::optional<int>& object_id,
              const Eigen::Vector3d& p_O);
  void Advance(double time_s);  // resets on time going back, forgets faded places

  Options options_;
  std::vector<Place> places_;
  std::optional<double> latest_time_s_;
};

}  // namespace saccade::mapping
