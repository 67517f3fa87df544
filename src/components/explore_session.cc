#include "saccade/components/explore_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "saccade/components/explore_attention.h"
#include "saccade/core/error.h"
#include "saccade/head/fixation.h"
#include "saccade/head/joint_profile.h"
#include "saccade/mapping/inhibition_3d.h"
#include "saccade/render/renderer.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {
namespace explore_internal {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::unique_ptr<render::Renderer> EyeRenderer(const scene::Scene& scene, bool truth) {
  render::RendererOptions options;
  options.cameras = {"left", "right"};
  options.truth_depth = truth;
  if (truth) options.cameras = {"left"};
  return render::MakeRenderer(scene, options);
}

scene::SceneState StateAt(const scene::Scene& scene, const Eigen::VectorXd& q, double time) {
  scene::SceneState state = scene.InitialState();
  state.time = time;
  state.joints = scene.robot()->head.State(q);
  return state;
}

// Back-projects every 4th pixel of a truth depth image into the world.
void AddTruth(const render::Frame& frame, double max_range, std::vector<Eigen::Vector3d>* out) {
  const geometry::CameraModel camera = vision::CameraModelOf(*frame.color);
  const geometry::Pose X_WC = vision::CameraPoseOf(*frame.color);
  const Image& depth = *frame.depth;
  for (int v = 0; v < depth.height(); v += 4) {
    const float* row = reinterpret_cast<const float*>(depth.data() + v * depth.stride());
    for (int u = 0; u < depth.width(); u += 4) {
      if (!(row[u] > 0)) continue;
      const std::optional<Eigen::Vector3d> ray = camera.Unproject(Eigen::Vector2d(u, v));
      if (!ray || ray->z() <= 0) continue;
      const Eigen::Vector3d p_C = *ray * (row[u] / ray->z());
      if (p_C.norm() > max_range) continue;
      out->push_back(X_WC * p_C);
    }
  }
}

// The time the head takes from q0 to q1 at rest (the slowest joint's time-optimal profile).
double SaccadeTime(const head::HeadModel& head, const Eigen::VectorXd& q0,
                   const Eigen::VectorXd& q1) {
  double longest = 0.0;
  for (int i = 0; i < head.num_joints(); ++i) {
    const head::JointSettings& joint = head.joint(i);
    if (!joint.driven || q0[i] == q1[i]) continue;
    const double target = std::clamp(q1[i], joint.limits.min, joint.limits.max);
    const double start = std::clamp(q0[i], joint.limits.min, joint.limits.max);
    longest = std::max(longest,
                       head::JointProfile::Plan(joint.limits, start, 0.0, target, 0.0).duration());
  }
  return longest;
}

Eigen::Vector3d InBase(const head::HeadModel& head, const Eigen::Vector3d& p_W) {
  return head.X_WB().inverse() * p_W;
}

}  // namespace explore_internal

using namespace explore_internal;

const std::vector<std::string>& ExploreStrategies() {
  static const std::vector<std::string> names = {"raster", "random", "saliency"};
  return names;
}

bool ExploreOptions::IsValid(std::string* error) const {
  std::string what;
  const auto positive = [&](const char* name, double value) {
    if (what.empty() && !(value > 0 && std::isfinite(value))) {
      what = std::string(name) + ": " + std::to_string(value) + ", expected a finite number > 0";
    }
  };
  const std::vector<std::string>& names = ExploreStrategies();
  if (std::find(names.begin(), names.end(), strategy) == names.end()) {
    what = "strategy: '" + strategy + "' does not exist, expected raster, random or saliency";
  }
  positive("seconds", seconds);
  positive("dwell_s", dwell_s);
  positive("target_distance_m", target_distance_m);
  positive("ior_time_constant_s", ior_time_constant_s);
  positive("ior_radius_m", ior_radius_m);
  positive("sample_every_s", sample_every_s);
  positive("truth_cell_m", truth_cell_m);
  if (what.empty() && !(raster_step > 0 && raster_step <= 2)) {
    what = "raster_step: " + std::to_string(raster_step) + ", expected (0, 2] fields of view";
  }
  if (what.empty() && !(candidate_step > 0 && candidate_step <= 2)) {
    what = "candidate_step: " + std::to_string(candidate_step) + ", expected (0, 2] fields of view";
  }
  if (what.empty() && !(truth_step > 0 && truth_step <= 2)) {
    what = "truth_step: " + std::to_string(truth_step) + ", expected (0, 2] fields of view";
  }
  if (what.empty() && !(saliency_weight >= 0 && novelty_weight >= 0 && tentative_value >= 0)) {
    what = "saliency_weight, novelty_weight, tentative_value: expected numbers >= 0";
  }
  std::string nested;
  if (what.empty() && !stereo.IsValid(&nested)) what = nested;
  if (what.empty() && !map.IsValid(&nested)) what = nested;
  if (what.empty()) return true;
  if (error) *error = "explore: " + what;
  return false;
}

namespace explore_internal {

void Check(const scene::Scene& scene, const ExploreOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
  if (!scene.robot()) throw InvalidArgument("explore: the scene has no robot to explore with");
}

}  // namespace explore_internal

ExploreTruth MakeExploreTruth(const scene::Scene& scene, const ExploreOptions& options) {
  Check(scene, options);
  const auto start = Clock::now();
  const head::HeadModel& head = scene.robot()->head;
  ExploreTruth truth;
  truth.viewpoint_W = head.X_WB().translation();
  truth.grid_W =
      ReachGrid(head, options.raster_step * EyeFieldOfView(head), options.target_distance_m);
  const std::vector<Eigen::Vector3d> views =
      ReachGrid(head, options.truth_step * EyeFieldOfView(head), options.target_distance_m);
  std::unique_ptr<render::Renderer> renderer = EyeRenderer(scene, true);
  head::FixationSolver solver(head);
  std::vector<Eigen::Vector3d> samples;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const head::FixationResult fixation = solver.Solve(views[i]);
    const std::vector<render::Frame> frames =
        renderer->Render(StateAt(scene, fixation.joints, 0.0), static_cast<int64_t>(i));
    AddTruth(frames.at(0), options.map.max_range_m, &samples);
  }
  truth.samples_W = mapping::Thin(samples, options.truth_cell_m);
  truth.views = static_cast<int>(views.size());
  truth.render_ms = MsSince(start);
  return truth;
}

namespace explore_internal {

// The strategy's next candidates, best first.
class Chooser {
 public:
  Chooser(const scene::Scene& scene, const ExploreOptions& options, const ExploreTruth& truth)
      : head_(scene.robot()->head),
        options_(options),
        truth_(truth),
        fov_(EyeFieldOfView(head_)),
        attention_(head_,
                   options.strategy == "saliency"
                       ? ReachGrid(head_, options.candidate_step * fov_, options.target_distance_m)
                       : std::vector<Eigen::Vector3d>{},
                   [&] {
                     ExploreAttention::Options o;
                     o.saliency_weight = options.saliency_weight;
                     o.novelty_weight = options.novelty_weight;
                     o.target_distance_m = options.target_distance_m;
                     o.tentative_value = options.tentative_value;
                     o.max_range_m = options.map.max_range_m;
                     return o;
                   }()),
        ior_([&] {
          mapping::Inhibition3d::Options o;
          o.time_constant_s = options.ior_time_constant_s;
          o.radius_m = options.ior_radius_m;
          return o;
        }()),
        random_(options.seed) {}

  std::vector<ExploreCandidate> Next(double time, const vision::StereoDepth* depth,
                                     const Image* left, const mapping::WorldMap* map) {
    if (options_.strategy == "raster") {
      const Eigen::Vector3d p = truth_.grid_W[next_raster_++ % truth_.grid_W.size()];
      return {{p, 0.0}};
    }
    if (options_.strategy == "random") {
      std::vector<ExploreCandidate> out;
      std::uniform_int_distribution<std::size_t> pick(0, truth_.grid_W.size() - 1);
      std::uniform_real_distribution<double> jitter(-0.5, 0.5);
      for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d p = truth_.grid_W[pick(random_)];
        const Eigen::Vector3d d = InBase(head_, p).normalized();
        const double azimuth = std::atan2(d.y(), d.x()) + jitter(random_) * fov_.x();
        const double elevation = std::asin(d.z()) + jitter(random_) * fov_.y();
        out.push_back(
            {head_.X_WB() * (options_.target_distance_m * DirectionOf(azimuth, elevation)), 0.0});
      }
      return out;
    }
    return attention_.Rank(
        depth, left, [&](const Eigen::Vector3d& p_W) { return ior_.Inhibition(p_W, time); }, map);
  }

  void Fixated(const Eigen::Vector3d& p_W, double time) {
    attention_.Looked(p_W);
    ior_.Visit(p_W, time);
  }

 private:
  const head::HeadModel& head_;
  const ExploreOptions& options_;
  const ExploreTruth& truth_;
  Eigen::Vector2d fov_;
  ExploreAttention attention_;
  mapping::Inhibition3d ior_;
  std::mt19937_64 random_;
  std::size_t next_raster_ = 0;
};

void Sample(const mapping::WorldMap& map, const ExploreTruth& truth, double time, int fixations,
            ExploreReport* report) {
  const auto start = Clock::now();
  mapping::ScoreOptions options;
  const mapping::MapScore score =
      mapping::ScoreMap(map.OccupiedCentres(), truth.samples_W, options);
  report->curve.push_back({time, fixations, score.completeness});
  if (report->time_to_50_s < 0 && score.completeness >= 0.5) report->time_to_50_s = time;
  if (report->time_to_80_s < 0 && score.completeness >= 0.8) report->time_to_80_s = time;
  report->costs.scoring_ms += MsSince(start);
}

}  // namespace explore_internal

ExploreReport Explore(const scene::Scene& scene, const ExploreOptions& options,
                      const ExploreTruth& truth, mapping::WorldMap* map_out,
                      const ExploreProgress& progress) {
  Check(scene, options);
  if (truth.grid_W.empty()) throw InvalidArgument("explore: the head reaches no direction");
  const auto run_start = Clock::now();
  const head::HeadModel& head = scene.robot()->head;
  ExploreReport report;
  report.strategy = options.strategy;
  std::unique_ptr<render::Renderer> renderer = EyeRenderer(scene, false);
  const vision::DenseStereo stereo(options.stereo);
  mapping::WorldMap map(options.map);
  Chooser chooser(scene, options, truth);
  head::FixationSolver solver(head);
  Eigen::VectorXd q = head.Posture(scene.InitialState().joints);
  double time = 0.0;
  double next_sample = 0.0;
  std::optional<vision::StereoDepth> depth;
  std::vector<render::Frame> frames;
  while (time < options.seconds) {
    auto start = Clock::now();
    const std::vector<ExploreCandidate> candidates = chooser.Next(
        time, depth ? &*depth : nullptr, frames.empty() ? nullptr : &*frames[0].color, &map);
    std::optional<head::FixationResult> fixation;
    Eigen::Vector3d target = Eigen::Vector3d::Zero();
    for (const ExploreCandidate& candidate : candidates) {
      head::FixationOptions fixation_options;
      fixation_options.seed = q;
      fixation_options.axis_tolerance = 1e-4;
      head::FixationResult result = solver.Solve(candidate.p_W, fixation_options);
      if (result.reachable()) {
        fixation = std::move(result);
        target = candidate.p_W;
        break;
      }
      ++report.unreachable_targets;
    }
    report.costs.attention_ms += MsSince(start);
    if (!fixation) {  // nothing reachable this step: look again after a dwell
      time += options.dwell_s;
      continue;
    }
    time += SaccadeTime(head, q, fixation->joints);
    if (time >= options.seconds) break;  // the run ends during the saccade
    report.saccade_amplitudes_deg.push_back((fixation->joints - q).cwiseAbs().maxCoeff() * 180 /
                                            M_PI);
    q = fixation->joints;

    start = Clock::now();
    frames = renderer->Render(StateAt(scene, q, time), report.fixations);
    report.costs.render_ms += MsSince(start);
    start = Clock::now();
    const Image& left = *frames.at(0).color;
    const Image& right = *frames.at(1).color;
    depth = stereo.Compute({&left, vision::CameraModelOf(left), vision::CameraPoseOf(left)},
                           {&right, vision::CameraModelOf(right), vision::CameraPoseOf(right)});
    report.costs.depth_ms += MsSince(start);
    start = Clock::now();
    map.Fuse(*depth);
    report.costs.fusion_ms += MsSince(start);
    chooser.Fixated(target, time);
    report.fixation_points_W.push_back(target);
    ++report.fixations;
    time += options.dwell_s;
    if (time >= next_sample) {
      Sample(map, truth, std::min(time, options.seconds), report.fixations, &report);
      next_sample +=
          options.sample_every_s * std::ceil((time - next_sample) / options.sample_every_s + 1e-9);
    }
    if (progress) progress(report.fixations, time);
  }
  report.seconds = std::min(time, options.seconds);
  Sample(map, truth, report.seconds, report.fixations, &report);
  const std::vector<Eigen::Vector3d> centres = map.OccupiedCentres();
  report.score = mapping::ScoreMap(centres, truth.samples_W);
  mapping::ScoreOptions band;
  band.viewpoint = truth.viewpoint_W;
  band.min_range_m = 1.0;
  band.max_range_m = 3.0;
  report.score_1_to_3m = mapping::ScoreMap(centres, truth.samples_W, band);
  report.map_voxels = map.occupied_voxels();
  report.map_bytes = map.memory_bytes();
  report.costs.total_ms = MsSince(run_start);
  if (map_out != nullptr) *map_out = std::move(map);
  return report;
}

}  // namespace saccade::components
