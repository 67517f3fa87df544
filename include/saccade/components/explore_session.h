#pragma once
// Exploration (issue 44, seed section 7.2): the head looks around a scene, fuses the dense
// stereo depth of every fixation into a world map, and is scored against the ground truth.
//
// One run, in simulated time (deterministic: the same scene, head and options give the same
// report and map, bit for bit):
//   1. choose the next fixation target (the strategy);
//   2. saccade there: the fixation posture (head/fixation.h, any head), reached in the
//      time-optimal joint profiles' time (head/joint_profile.h: the slowest joint);
//   3. at rest, capture both eyes (the renderer, with the scene's lens and noise), compute the
//      dense stereo depth (vision/dense_stereo.h) and fuse it into the map
//      (mapping/world_map.h); the place fixated is inhibited (inhibition of return);
//   4. dwell `dwell_s` (capture and processing), then go on until `seconds` have passed.
//
// The strategies:
//   raster   -- a boustrophedon scan of the head's reach: a grid of directions from the head's
//               base, spaced `raster_step` fields of view, row by row;
//   random   -- random saccades to reachable directions (seeded);
//   saliency -- two-stage attention: the spectral-residual saliency of the whole left image
//               proposes zones (the first stage), each zone's peak becomes a 3D candidate
//               through the stereo depth; a grid of the reach spaced `candidate_step` fields of
//               view gives candidates too; each candidate scores saliency_weight * saliency +
//               novelty_weight * novelty, less its inhibition of return and 0.1 per radian of
//               turn from the current gaze; the best one is fixated. Novelty comes from the map:
//               a grid of rays across the candidate's view, each scored by what it meets first
//               (RayNovelty: unknown space, the map's frontier, 1; a surface seen once and not
//               yet occupied, tentative_value; the mapped surface or free space to the range, 0).
//
// The ground truth: the renderer's depth from a dense grid of the head's reach (truth_step),
// back-projected and thinned to one sample per truth_cell_m, within the map's range: the surface
// the head can see. Completeness and accuracy as mapping/map_score.h defines them.
#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "saccade/components/explore_attention.h"
#include "saccade/mapping/map_score.h"
#include "saccade/mapping/world_map.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/dense_stereo.h"

namespace saccade::components {

/// The strategies, by name: "raster", "random", "saliency".
const std::vector<std::string>& ExploreStrategies();

struct ExploreOptions {
  std::string strategy = "saliency";  ///< one of ExploreStrategies()
  double seconds = 30.0;              ///< simulated time, > 0
  double dwell_s = 0.2;               ///< time at each fixation (capture, processing), > 0
  uint64_t seed = 1;                  ///< random saccades' and tie-breaking seed
  double target_distance_m = 2.0;     ///< directions become targets at this distance, > 0
  double raster_step = 0.75;          ///< raster spacing, in fields of view: (0, 2]
  /// The saliency strategy's candidates beside its saliency zones: a grid of the reach spaced
  /// this many fields of view: (0, 2].
  double candidate_step = 0.375;
  double saliency_weight = 1.0;  ///< >= 0
  double novelty_weight = 1.0;   ///< >= 0
  /// Novelty of a ray that meets a surface seen once (hit, not yet occupied: one more sighting
  /// maps it) against one that meets unknown space (1): >= 0. See RayNovelty.
  double tentative_value = 2.0;
  double ior_time_constant_s = 10.0;  ///< inhibition of a fixated place decays so, > 0
  double ior_radius_m = 0.3;          ///< size of an inhibited place, > 0
  double sample_every_s = 1.0;        ///< completeness is measured this often, > 0
  double truth_cell_m = 0.01;         ///< truth samples: one per cube of this edge, > 0
  /// The truth is rendered from a grid of the head's reach spaced this many fields of view:
  /// (0, 2]. Finer than any strategy's views, so that it holds what they could see.
  double truth_step = 0.375;
  /// Full size (scale 1), not the automatic half size on POPEYE: half size's depth errs 13-17
  /// mm RMS at 2.6-3.2 m, so that two sightings of a far surface often fall in different voxels
  /// and the map stays incomplete (71 % of the wall at 20 s against 83 % at full size, for about
  /// four times the stereo's cost; bench/baselines/explore-2core.md).
  vision::DenseStereo::Options stereo = [] {
    vision::DenseStereo::Options o;
    o.scale = 1.0;
    return o;
  }();
  mapping::WorldMap::Options map;

  bool IsValid(std::string* error) const;
};

/// One point of the completeness curve.
struct CompletenessSample {
  double time_s = 0.0;
  int fixations = 0;
  double completeness = 0.0;
};

/// Cumulative wall-clock cost of the stages, milliseconds.
struct ExploreCosts {
  double render_ms = 0.0;
  double depth_ms = 0.0;
  double fusion_ms = 0.0;
  double attention_ms = 0.0;
  double scoring_ms = 0.0;
  double total_ms = 0.0;  ///< the whole run, the truth's rendering excluded
};

struct ExploreReport {
  std::string strategy;
  double seconds = 0.0;                        ///< simulated time run
  int fixations = 0;                           ///< fixations made (stereo pairs fused)
  int unreachable_targets = 0;                 ///< targets fixation could not reach (skipped)
  std::vector<double> saccade_amplitudes_deg;  ///< the largest joint change of each saccade
  std::vector<CompletenessSample> curve;
  /// Simulated time at which completeness first reached 0.5 and 0.8 (< 0: never).
  double time_to_50_s = -1.0;
  double time_to_80_s = -1.0;
  mapping::MapScore score;          ///< the final map against the whole truth
  mapping::MapScore score_1_to_3m;  ///< map points and truth 1-3 m from the head
  int64_t map_voxels = 0;
  std::size_t map_bytes = 0;
  ExploreCosts costs;
  std::vector<Eigen::Vector3d> fixation_points_W;  ///< every target fixated, in order
};

/// `saccade explore`'s settings file (config/explore.yaml documents it): the strategies to
/// compare and the options they share.
struct ExploreConfig {
  std::vector<std::string> strategies = ExploreStrategies();
  ExploreOptions options;
};

/// Reads a settings file. Every error throws FileError "file:line: key: what was expected, what
/// was got": an unknown key, a strategy that does not exist, a value out of its range (a map
/// resolution of 0, a time constant of -1, ...).
ExploreConfig LoadExploreConfig(const std::filesystem::path& path);

/// The ground truth's surface samples and the raster grid, computed once per scene and head
/// and shared by every strategy of a comparison.
struct ExploreTruth {
  std::vector<Eigen::Vector3d> samples_W;  ///< surface samples (world, m)
  std::vector<Eigen::Vector3d> grid_W;     ///< the raster's targets (world, m), in scan order
  Eigen::Vector3d viewpoint_W = Eigen::Vector3d::Zero();  ///< the head's base origin
  int views = 0;                                          ///< postures the truth was rendered from
  double render_ms = 0.0;
};

/// Progress: (fixations so far, simulated seconds so far).
using ExploreProgress = std::function<void(int fixations, double time_s)>;

/// The truth of `scene` (its robot, at its initial pose). Throws InvalidArgument when the scene
/// has no robot or the options are invalid.
ExploreTruth MakeExploreTruth(const scene::Scene& scene, const ExploreOptions& options);

/// One exploration run; `map` receives the final map (may be null). Throws InvalidArgument
/// naming the option when the options are invalid, and when the scene has no robot.
ExploreReport Explore(const scene::Scene& scene, const ExploreOptions& options,
                      const ExploreTruth& truth, mapping::WorldMap* map = nullptr,
                      const ExploreProgress& progress = {});

}  // namespace saccade::components
