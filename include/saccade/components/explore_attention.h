#pragma once
// Two-stage attention for exploration (seed 7.2, issue 44), shared by `saccade explore` (its
// saliency strategy) and the pipeline component vision.explore:
//   1. the saliency stage (vision/saliency.h, spectral residual) finds the zones of interest of
//      the whole left image; each zone's peak, at the stereo depth found there, is a candidate;
//   2. every direction of the head's reach (a grid, ReachGrid) is a candidate too, at the
//      target distance.
// A candidate p scores
//   saliency_weight * saliency(p) + novelty_weight * novelty(p) - inhibition(p) - turn_weight *
//   turn
// where novelty is, with a map, what the rays across p's view meet first (RayNovelty: unknown
// space, a surface seen once), and without one the share of a field of view about p's direction
// never looked at (2-degree cells of azimuth and elevation from the head's base), inhibition is
// inhibition of return in 3D (the caller's: mapping/inhibition_3d.h), and turn the angle (rad)
// from where the eyes look now, so that among equals the nearer saccade wins. Deterministic: the
// same inputs give the same ranking.
//
// The second stage (`second_stage_faces`): only the best-scoring saliency zone is examined
// further, at the image's full resolution: faces are searched in its box (grown by half on
// each side), and each accepted face, at the stereo depth of its centre, becomes a candidate
// scoring face_weight above that zone (the task: faces first). The first stage works on a
// 64-pixel-wide image; the second searches a crop, not the whole image (the seed's two-stage
// model, its section 7.2 and reference [15]).
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/head/head_model.h"
#include "saccade/mapping/world_map.h"
#include "saccade/vision/dense_stereo.h"
#include "saccade/vision/face_detector.h"
#include "saccade/vision/saliency.h"

namespace saccade::components {

/// A base-frame direction (azimuth about z, elevation), unit length.
Eigen::Vector3d DirectionOf(double azimuth, double elevation);

/// The head's eye field of view (rad): the left camera's, horizontal and vertical.
Eigen::Vector2d EyeFieldOfView(const head::HeadModel& head);

/// The head's reach, sampled: the points at `distance` (m) along base-frame directions on an
/// azimuth x elevation grid spaced `step` (rad, per axis) that fixation reaches; rows from the
/// top, each row's direction alternating (a boustrophedon: the raster's scan order).
std::vector<Eigen::Vector3d> ReachGrid(const head::HeadModel& head, const Eigen::Vector2d& step,
                                       double distance);

/// The novelty of one direction from the map: what a ray from `origin_W` along `direction_W`
/// meets first (mapping::WorldMap::FirstAlong) within `max_range_m`: unknown space (a frontier)
/// 1, halved for each of the `looks` fixations that already looked that way without mapping it
/// (stereo found nothing there: sky, a textureless floor); a surface seen once, not yet
/// occupied, `tentative_value`, halved for each look past the second (two sightings that still
/// fall in different voxels: far, noisy stereo); the map's surface, or nothing within range, 0.
double RayNovelty(const mapping::WorldMap& map, const Eigen::Vector3d& origin_W,
                  const Eigen::Vector3d& direction_W, double max_range_m, int looks,
                  double tentative_value);

/// A target attention proposes: where (world, m), its score, and what proposed it.
struct ExploreCandidate {
  enum class Source { kReach, kSaliency, kFace };
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  double score = 0.0;
  Source source = Source::kReach;
};

class ExploreAttention {
 public:
  struct Options {
    double saliency_weight = 1.0;
    double novelty_weight = 1.0;
    double turn_weight = 0.1;        ///< per radian of saccade
    double target_distance_m = 2.0;  ///< of a candidate without a depth
    /// Novelty from a map: a ray meeting a surface seen once (RayNovelty), against unknown's 1.
    double tentative_value = 2.0;
    double max_range_m = 5.0;         ///< novelty rays: the map's range
    bool second_stage_faces = false;  ///< search faces in the best saliency zone
    double face_weight = 2.0;         ///< a face scores this above its zone
  };
  /// The inhibition of return of a world point, in [0, 1].
  using Inhibition = std::function<double(const Eigen::Vector3d& p_W)>;

  /// `grid_W`: the head's reach (ReachGrid), the candidates every ranking has.
  ExploreAttention(const head::HeadModel& head, std::vector<Eigen::Vector3d> grid_W,
                   const Options& options);

  /// The candidates, best first: the saliency zones of `left` (a camera image with its
  /// calibration and pose, vision/image_camera.h) placed at the stereo depth `depth` when both
  /// are given, and the reach grid.
  /// With `map`, novelty is the map's (ViewNovelty); without, the share of the view never
  /// looked at.
  std::vector<ExploreCandidate> Rank(const vision::StereoDepth* depth, const Image* left,
                                     const Inhibition& inhibition,
                                     const mapping::WorldMap* map = nullptr);

  /// The eyes fixated p_W: its field of view is no longer novel, and turns start from it.
  void Looked(const Eigen::Vector3d& p_W);

  /// The novelty of the view about the world point p_W: with a map, the mean RayNovelty of a
  /// 7 x 7 grid of rays across 0.9 of the field of view from the head's base (0.3 m out);
  /// without, the share of the view's 2-degree cells never looked at, in [0, 1].
  double Novelty(const Eigen::Vector3d& p_W, const mapping::WorldMap* map = nullptr) const;

  const std::vector<Eigen::Vector3d>& grid_W() const { return grid_W_; }

 private:
  double DepthAlong(const vision::StereoDepth& depth, const Eigen::Vector3d& ray_W) const;
  // The second stage: faces in `zone` of `left` at full resolution, as candidates.
  void FacesIn(const cv::Rect& zone, const Image& left, const vision::StereoDepth& depth,
               double zone_score, std::vector<ExploreCandidate>* out);
  template <typename F>
  void ForEachCell(const Eigen::Vector3d& direction_B, const Eigen::Vector2d& fov, F&& f) const;
  int Looks(const Eigen::Vector3d& direction_B) const;  // fixations that looked along it
  Eigen::Vector3d InBase(const Eigen::Vector3d& p_W) const;

  const head::HeadModel& head_;
  std::vector<Eigen::Vector3d> grid_W_;
  Options options_;
  Eigen::Vector2d fov_;
  vision::SpectralResidualSaliency saliency_;
  std::unique_ptr<vision::FaceDetector> faces_;  // the second stage's, when on
  std::vector<uint8_t> looks_;  // 2-degree cells, azimuth x elevation: the fixations that held each
  Eigen::Vector3d gaze_B_ = Eigen::Vector3d::UnitX();
};

}  // namespace saccade::components
