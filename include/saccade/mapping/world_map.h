#pragma once
// The world map fused from depth (issue 44, item 2): an occupancy octree (OctoMap, Hornung et
// al. 2013), anchored to the world frame W (z up, metres). Every depth image is inserted as
// rays from its camera's optical centre: the voxel at a ray's end is a hit (more likely
// occupied), the voxels it crosses are misses (more likely free), each a log-odds update clamped
// to OctoMap's bounds, so that a surface seen again and again stays and a stray match fades. The
// map knows three kinds of space, which exploration needs: occupied, free and unknown (never
// crossed by a ray).
//
// Why OctoMap (measured against the alternatives Debian 12 offers;
// bench/baselines/explore-2core.md): it is two packages (Open3D's TSDF brings 79, PCL 508); it
// holds free and unknown space, which novelty and frontiers are made of, where a TSDF holds
// surfaces only near them; and its surface, the centres of occupied voxels, is within half a voxel
// of the truth plus the stereo's own error, well inside the 2 cm the issue asks at the default 2 cm
// voxels.
//
// OctoMap stays private to this module: its types appear in no public header.
#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "saccade/core/interval.h"
#include "saccade/vision/dense_stereo.h"

namespace saccade::mapping {

/// What a voxel of the map holds.
enum class Occupancy { kUnknown, kFree, kOccupied };

/// What a ray through the map meets first (WorldMap::FirstAlong).
enum class RayEnd {
  kUnknown,    ///< unknown space: a frontier of the map lies that way
  kTentative,  ///< a voxel hit more than missed but not yet occupied (a surface seen once)
  kOccupied,   ///< the map's surface
  kNothing,    ///< free space all the way to the range
};

/// What one insertion did.
struct FuseStats {
  int64_t rays = 0;          ///< depth samples inserted (after stride, confidence and range)
  int64_t occupied = 0;      ///< occupied voxels in the map afterwards
  int64_t known_voxels = 0;  ///< finest voxels known (occupied or free) afterwards
};

/// The occupancy map. Not thread-safe. A copy is a snapshot: fusing into one changes nothing
/// in the other (mapping.world_map hands its readers one each time it has fused).
class WorldMap {
 public:
  struct Options {
    double resolution_m = 0.02;  ///< edge of the finest voxel: kResolutions
    /// Depth samples farther than this (along the ray) are not inserted: kRanges.
    double max_range_m = 5.0;
    /// Every stride-th row and column of a depth image is inserted: kStrides.
    int stride = 2;
    /// Samples of lower confidence (vision::StereoDepth::confidence) are left out: [0, 1].
    double min_confidence = 0.5;
    /// A depth sample whose 4 neighbours differ from it by more than this share of its depth,
    /// or are unmatched, lies on an edge and is left out: > 0.
    double edge_ratio = 0.01;
    double hit_probability = 0.7;   ///< OctoMap's sensor model: (0.5, 1)
    double miss_probability = 0.4;  ///< (0, 0.5)
    /// A voxel is occupied above this probability: (0, 1). 0.75 with the default hit of 0.7
    /// takes two hits (0.7, then 0.84): a surface seen by two fixations, which a stereo
    /// mismatch seldom is; 0.5 maps a surface at its first sighting, mismatches too.
    double occupancy_threshold = 0.75;

    static constexpr Interval kResolutions = Interval::Closed(0.001, 1.0);
    static constexpr Interval kRanges = Interval::Above(0.0);
    static constexpr Interval kStrides = Interval::Closed(1, 64);
    static constexpr Interval kConfidences = Interval::Closed(0.0, 1.0);
    static constexpr Interval kEdgeRatios = Interval::Above(0.0);
    static constexpr Interval kHits = Interval{0.5, 1.0, true, true};
    static constexpr Interval kMisses = Interval{0.0, 0.5, true, true};
    static constexpr Interval kThresholds = Interval{0.0, 1.0, true, true};

    bool IsValid(std::string* error) const;
  };

  /// Throws InvalidArgument with IsValid's message.
  explicit WorldMap(const Options& options);
  ~WorldMap();
  WorldMap(const WorldMap& other);
  WorldMap(WorldMap&&) noexcept;
  WorldMap& operator=(WorldMap&&) noexcept;
  WorldMap& operator=(const WorldMap&) = delete;

  /// Inserts a stereo depth image (its rays start at X_WR's origin): every stride-th sample of
  /// at least min_confidence that is not on a depth edge (edge_ratio).
  FuseStats Fuse(const vision::StereoDepth& depth);
  /// Inserts world points seen from `origin_W` (each a hit, the ray to it misses).
  FuseStats FusePoints(const std::vector<Eigen::Vector3d>& points_W,
                       const Eigen::Vector3d& origin_W);

  /// The state of the voxel holding p_W.
  Occupancy At(const Eigen::Vector3d& p_W) const;
  /// The centres of the occupied voxels (the map's surface), in the octree's order
  /// (deterministic for the same insertions).
  std::vector<Eigen::Vector3d> OccupiedCentres() const;
  /// The first voxel along a ray from `origin_W` (direction_W need not be unit) that is not
  /// free, within `max_range_m`; *distance_m (when not null) is set to its distance (max_range_m
  /// for kNothing). The voxel holding the origin is not looked at. Safe to call from several
  /// threads at once while nothing is fused.
  RayEnd FirstAlong(const Eigen::Vector3d& origin_W, const Eigen::Vector3d& direction_W,
                    double max_range_m, double* distance_m = nullptr) const;

  /// The finest voxels occupied, and known (occupied or free): counts kept by every insertion,
  /// constant time.
  int64_t occupied_voxels() const;
  int64_t known_voxels() const;
  std::size_t memory_bytes() const;  ///< the octree's own estimate
  const Options& options() const { return options_; }

  /// Writes the occupied centres as a binary little-endian PLY point cloud (x, y, z float, in
  /// metres, world frame), through a temporary file renamed at the end: a failed write leaves
  /// no half file. Throws FileError naming the path.
  void WritePly(const std::filesystem::path& path) const;

 private:
  struct Impl;
  Options options_;
  std::unique_ptr<Impl> impl_;
};

/// Writes points as a binary little-endian PLY (x, y, z float), atomically (see WritePly).
void WritePointsPly(const std::vector<Eigen::Vector3d>& points, const std::filesystem::path& path);

}  // namespace saccade::mapping
