#pragma once
// A map scored against the ground truth only a simulator has (issue 44, item 5).
//
// The truth is a set of surface samples in the world (the renderer's depth images of the
// surfaces the head can see, back-projected), thinned to one sample per `cell_m` cube. Against
// it a map's points (world, metres) give:
//   completeness: the share of truth samples with a map point within `within_m` (2 cm): how
//     much of the visible surface the map holds;
//   accuracy: each map point's distance to the nearest truth sample (mean, RMS, 95th
//     percentile): how far the map lies from the surface.
// Both may be restricted to a band of ranges from a viewpoint (the 1-3 m).
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

namespace saccade::mapping {

/// Points in a hash of cubes, for nearest-neighbour queries within a bounded radius.
class PointGrid {
 public:
  /// `cell_m` > 0: queries are exact up to this radius (larger ones are clipped to it).
  PointGrid(const std::vector<Eigen::Vector3d>& points, double cell_m);
  /// The distance to the nearest point if one lies within `radius_m` (<= cell_m).
  std::optional<double> Nearest(const Eigen::Vector3d& p, double radius_m) const;
  std::size_t size() const { return points_.size(); }

  /// The cube of edge `cell_m` that holds p, and a hash of such cubes (Thin uses them too).
  static Eigen::Vector3i KeyOf(const Eigen::Vector3d& p, double cell_m);
  struct KeyHash {
    std::size_t operator()(const Eigen::Vector3i& k) const;
  };

 private:
  Eigen::Vector3i Key(const Eigen::Vector3d& p) const;
  double cell_m_;
  std::vector<Eigen::Vector3d> points_;
  std::unordered_map<Eigen::Vector3i, std::vector<uint32_t>, KeyHash> cells_;
};

/// One sample per `cell_m` cube of `points` (the first one met, so the result is deterministic).
std::vector<Eigen::Vector3d> Thin(const std::vector<Eigen::Vector3d>& points, double cell_m);

struct MapScore {
  int64_t truth_samples = 0;  ///< truth samples considered (in the range band)
  int64_t map_points = 0;     ///< map points considered (in the range band)
  double completeness = 0.0;  ///< share of truth samples with a map point within within_m
  double mean_m = 0.0;        ///< map point -> nearest truth sample
  double rms_m = 0.0;
  double p95_m = 0.0;
  /// Map points with no truth sample within `far_m` (counted at far_m in the figures above):
  /// surfaces the map holds that the truth does not (mismatches).
  int64_t outliers = 0;
};

struct ScoreOptions {
  double within_m = 0.02;  ///< a truth sample is covered by a map point this close
  double far_m = 0.05;     ///< accuracy distances are capped here (their points are outliers)
  /// A band of ranges from `viewpoint`: points outside [min_range_m, max_range_m] are left out.
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();
  double min_range_m = 0.0;
  double max_range_m = 1e9;
};

/// Scores `map_points` against `truth` (both world, metres).
MapScore ScoreMap(const std::vector<Eigen::Vector3d>& map_points,
                  const std::vector<Eigen::Vector3d>& truth, const ScoreOptions& options = {});

}  // namespace saccade::mapping
