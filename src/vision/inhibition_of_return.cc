#include "saccade/vision/inhibition_of_return.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "saccade/core/error.h"

namespace saccade::vision {

bool InhibitionOfReturn::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kDwells.Contains(fixation_time_s)) {
    what = kDwells.Refusal("fixation_time_s", fixation_time_s);
  } else if (!kRadii.Contains(radius_m)) {
    what = kRadii.Refusal("radius_m", radius_m);
  } else if (!kSuppressions.Contains(suppression_time_s)) {
    what = kSuppressions.Refusal("suppression_time_s", suppression_time_s);
  }
  if (what.empty()) return true;
  if (error) *error = "InhibitionOfReturn::Options: " + what;
  return false;
}

InhibitionOfReturn::InhibitionOfReturn() : InhibitionOfReturn(Options()) {}

InhibitionOfReturn::InhibitionOfReturn(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

bool InhibitionOfReturn::IsSuppressed(const Eigen::Vector3d& p_W, double time_s) const {
  return std::any_of(suppressions_.begin(), suppressions_.end(), [&](const Suppression& s) {
    return time_s < s.until_s && (p_W - s.p_W).norm() <= options_.radius_m;
  });
}

std::optional<std::size_t> InhibitionOfReturn::Select(
    double time_s, std::span<const Eigen::Vector3d> candidates_W, const Eigen::Vector3d& p_W_viewer,
    const std::optional<Eigen::Vector3d>& p_W_fixation) {
  if (started_ && time_s < last_time_) {  // time went back: a new run
    suppressions_.clear();
    dwelling_ = false;
  }
  started_ = true;
  last_time_ = time_s;
  std::erase_if(suppressions_, [&](const Suppression& s) { return time_s >= s.until_s; });
  // Following, a suppression that found its object this step suppresses that candidate only
  // (taken); one that did not suppresses its place.
  std::vector<bool> taken(candidates_W.size(), false);
  std::vector<bool> attached(suppressions_.size(), false);
  if (options_.follow) {
    // Each suppressed place moves to the nearest candidate within radius_m not yet taken.
    for (std::size_t k = 0; k < suppressions_.size(); ++k) {
      Suppression& s = suppressions_[k];
      std::optional<std::size_t> nearest;
      double nearest_distance = options_.radius_m;
      for (std::size_t i = 0; i < candidates_W.size(); ++i) {
        if (taken[i] || !candidates_W[i].allFinite()) continue;
        const double d = (candidates_W[i] - s.p_W).norm();
        if (d <= nearest_distance) {
          nearest_distance = d;
          nearest = i;
        }
      }
      if (nearest) {
        taken[*nearest] = true;
        attached[k] = true;
        s.p_W = candidates_W[*nearest];
      }
    }
  }

  // Dwell: the fixation stays within radius_m of where it began (following: of where it was
  // at the last step). Fixating a place already suppressed does not start a new dwell (it
  // would only extend the suppression).
  if (!p_W_fixation || IsSuppressed(*p_W_fixation, time_s)) {
    dwelling_ = false;
  } else if (!dwelling_ || (*p_W_fixation - dwell_p_W_).norm() > options_.radius_m) {
    dwelling_ = true;
    dwell_p_W_ = *p_W_fixation;
    dwell_start_ = time_s;
  } else if (options_.follow) {
    dwell_p_W_ = *p_W_fixation;
  }
  if (dwelling_ && time_s - dwell_start_ >= options_.fixation_time_s) {
    suppressions_.push_back({dwell_p_W_, time_s + options_.suppression_time_s});
    attached.push_back(false);
    dwelling_ = false;
  }

  std::optional<std::size_t> best;
  double best_distance = std::numeric_limits<double>::infinity();
  const auto suppressed = [&](std::size_t i) {
    if (taken[i]) return true;
    for (std::size_t k = 0; k < attached.size(); ++k) {
      if (!attached[k] && (candidates_W[i] - suppressions_[k].p_W).norm() <= options_.radius_m) {
        return true;
      }
    }
    return false;
  };
  for (std::size_t i = 0; i < candidates_W.size(); ++i) {
    if (!candidates_W[i].allFinite() || suppressed(i)) continue;
    const double d = (candidates_W[i] - p_W_viewer).norm();
    if (d < best_distance) {
      best_distance = d;
      best = i;
    }
  }
  return best;
}

}  // namespace saccade::vision
