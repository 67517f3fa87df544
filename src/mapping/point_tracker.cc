#include "saccade/mapping/point_tracker.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "saccade/core/error.h"

namespace saccade::mapping {

bool PointTracker::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kGates.Contains(gate_m)) {
    what = kGates.Refusal("gate_m", gate_m);
  } else if (!kLostAfter.Contains(lost_after_s)) {
    what = kLostAfter.Refusal("lost_after_s", lost_after_s);
  }
  if (what.empty()) return true;
  if (error) *error = "PointTracker::Options: " + what;
  return false;
}

PointTracker::PointTracker() : PointTracker(Options()) {}

PointTracker::PointTracker(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

std::vector<int> PointTracker::Update(const std::vector<Eigen::Vector3d>& points_W, double time_s) {
  std::vector<int> ids(points_W.size(), -1);
  if (!std::isfinite(time_s)) return ids;
  if (latest_s_ && time_s < *latest_s_) tracks_.clear();  // a new run
  latest_s_ = time_s;
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const Track& track) {
                                 return time_s - track.seen_s > options_.lost_after_s;
                               }),
                tracks_.end());
  // Every pair within the gate, closest first (ties: track, then point order).
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    for (std::size_t p = 0; p < points_W.size(); ++p) {
      if (!points_W[p].allFinite()) continue;
      const double d = (points_W[p] - tracks_[t].p_W).norm();
      if (d <= options_.gate_m) pairs.emplace_back(d, t, p);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<bool> track_taken(tracks_.size(), false);
  for (const auto& [d, t, p] : pairs) {
    if (track_taken[t] || ids[p] >= 0) continue;
    track_taken[t] = true;
    ids[p] = tracks_[t].id;
    tracks_[t].p_W = points_W[p];
    tracks_[t].seen_s = time_s;
  }
  for (std::size_t p = 0; p < points_W.size(); ++p) {
    if (ids[p] >= 0 || !points_W[p].allFinite()) continue;
    ids[p] = next_id_++;
    tracks_.push_back({ids[p], points_W[p], time_s});
  }
  return ids;
}

std::optional<PointTracker::Track> PointTracker::SeenNear(const Eigen::Vector3d& p_W,
                                                          double within_m) const {
  std::optional<Track> best;
  double best_d = within_m;
  for (const Track& track : tracks_) {
    if (!latest_s_ || track.seen_s != *latest_s_) continue;
    const double d = (track.p_W - p_W).norm();
    if (d <= best_d) {
      best_d = d;
      best = track;
    }
  }
  return best;
}

}  // namespace saccade::mapping
