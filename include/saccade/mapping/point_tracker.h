#pragma once
// Ids for points that a detector finds anew in every frame (faces triangulated by both eyes,
// components/messages.h's CandidatesMessage): each point of a frame continues the track it is
// nearest to, so that what is anchored to a track (a place of inhibition of return,
// mapping/inhibition_3d.h) follows the object as it moves, on simulated and real cameras alike.
//
// Association is greedy by distance: of every (track, point) pair within gate_m, the closest
// pair is joined first, then the closest of what is left, and so on; a point left over starts a
// new track (ids 0, 1, 2, ... never reused). A track not seen for more than lost_after_s is
// dropped. An object moving farther than gate_m between two updates is taken for a new one: the
// gate is the step of the fastest object followed (0.25 m: a face walking at 1.5 m/s seen at
// 6 Hz).
//
// Time: seconds on one clock; an update at an earlier time than the latest is a new run (a
// simulation reset) and drops every track first. State, not thread-safe.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/interval.h"

namespace saccade::mapping {

class PointTracker {
 public:
  struct Options {
    double gate_m = 0.25;       ///< a point joins a track at most this far from it, m: kGates
    double lost_after_s = 1.0;  ///< a track unseen this long is dropped, s: kLostAfter
    static constexpr Interval kGates = Interval::LeftOpen(0, 1e6);
    static constexpr Interval kLostAfter = Interval::Closed(0, 1e9);
    /// Whether every field is in its range; if not, `error` (when not null) names the first
    /// field out of range, its value and the range expected.
    bool IsValid(std::string* error) const;
  };

  struct Track {
    int id = 0;
    Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< where it was last seen, world, m
    double seen_s = 0.0;                            ///< when
  };

  PointTracker();  ///< default Options
  /// Throws InvalidArgument with IsValid's message.
  explicit PointTracker(const Options& options);

  /// The points of one frame at time_s: joins each to a track (see the file comment) and
  /// returns the id of each, in the order given. Points that are not finite get -1 and touch no
  /// track; a time that is not finite changes nothing and gives -1 for every point.
  std::vector<int> Update(const std::vector<Eigen::Vector3d>& points_W, double time_s);

  /// The track seen at the latest update that is nearest p_W, within `within_m`; nullopt when
  /// none is.
  std::optional<Track> SeenNear(const Eigen::Vector3d& p_W, double within_m) const;

  const std::vector<Track>& tracks() const { return tracks_; }
  const Options& options() const { return options_; }

 private:
  Options options_;
  std::vector<Track> tracks_;
  int next_id_ = 0;
  std::optional<double> latest_s_;
};

}  // namespace saccade::mapping
