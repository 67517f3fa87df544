#pragma once
// Inhibition of return (seed section 7.2): once the head has fixated a place for
// `fixation_time_s`, that place (a ball of `radius_m` about where it was fixated) is
// suppressed for `suppression_time_s`, so that the next target selection skips it and the
// head moves on to the next closest face: a run visits every portrait in turn. With
// `follow` (the default, after the seed's reference [15]) a suppressed place moves with the
// object in it: at each step it moves to the nearest candidate within radius_m (each candidate
// carries one suppression at most), and a dwell goes on while the fixation moves by less than
// radius_m a step, so a face that moves is visited once.
#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "saccade/core/interval.h"

namespace saccade::vision {

/// Target selection with inhibition of return. State (not thread-safe); one per head.
class InhibitionOfReturn {
 public:
  struct Options {
    double fixation_time_s = 2.0;      ///< dwell before a place is suppressed, s: kDwells
    double radius_m = 0.15;            ///< size of a fixated / suppressed place, m: kRadii
    double suppression_time_s = 10.0;  ///< how long it stays suppressed, s: kSuppressions
    bool follow = true;                ///< suppressions and the dwell follow moving objects

    // The valid values, stated once: IsValid checks them, and vision.attention declares its
    // parameters with them (runtime::ParamDecl::Range(const Interval&)).
    static constexpr Interval kDwells = Interval::LeftOpen(0, 1e6);
    static constexpr Interval kRadii = Interval::LeftOpen(0, 1e6);
    static constexpr Interval kSuppressions = Interval::LeftOpen(0, 1e9);

    bool IsValid(std::string* error) const;
  };

  /// A suppressed place.
  struct Suppression {
    Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< where it was fixated (world, m)
    double until_s = 0.0;                           ///< suppressed while time < until_s
  };

  InhibitionOfReturn();  ///< default Options
  /// Throws InvalidArgument with IsValid's message.
  explicit InhibitionOfReturn(const Options& options);

  /// One step at `time_s` (non-decreasing; an earlier time resets the state): records the
  /// current fixation (std::nullopt: none, e.g. during a saccade) and returns the index of
  /// the candidate to fixate next: the closest to `p_W_viewer` among those not suppressed,
  /// std::nullopt when every candidate is suppressed or there is none. Never throws.
  std::optional<std::size_t> Select(double time_s, std::span<const Eigen::Vector3d> candidates_W,
                                    const Eigen::Vector3d& p_W_viewer,
                                    const std::optional<Eigen::Vector3d>& p_W_fixation);

  /// Whether a world point lies in a place suppressed at `time_s`.
  bool IsSuppressed(const Eigen::Vector3d& p_W, double time_s) const;
  /// The places suppressed at the last Select.
  const std::vector<Suppression>& suppressions() const { return suppressions_; }
  /// Seconds the current place has been fixated (0 when none).
  double dwell_s() const { return dwelling_ ? last_time_ - dwell_start_ : 0.0; }

 private:
  Options options_;
  std::vector<Suppression> suppressions_;
  bool dwelling_ = false;
  Eigen::Vector3d dwell_p_W_ = Eigen::Vector3d::Zero();
  double dwell_start_ = 0.0;
  double last_time_ = 0.0;
  bool started_ = false;
};

}  // namespace saccade::vision
