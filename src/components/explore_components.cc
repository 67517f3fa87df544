#include "saccade/components/explore_components.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "components/internal_frames.h"
#include "components/internal_scene.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/head/fixation.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {

using internal::FrameOf;

// ---- vision.dense_stereo ----

DenseStereoComponent::DenseStereoComponent()
    : left_(AddInput<runtime::ImageMessage>("left", /*required=*/true)),
      right_(AddInput<runtime::ImageMessage>("right", /*required=*/true)),
      joints_(AddInput<JointStateMessage>("joints")),
      depth_(AddOutput<DepthMessage>("depth")) {
  using O = vision::DenseStereo::Options;
  DeclareParam("scale", &options_.scale,
               "rectified size against the camera's (0: from the baseline, f B >= 129 px m)")
      .Range(O::kScales);
  DeclareParam("min_depth_m", &options_.min_depth_m,
               "nearest depth matched (sets the disparity range)")
      .Range(O::kMinDepths)
      .Unit("m");
  DeclareParam("block_size", &options_.block_size, "SGBM's matched block, odd")
      .Range(O::kBlockSizes)
      .Unit("px");
  DeclareParam("uniqueness_ratio", &options_.uniqueness_ratio,
               "the best cost must beat the second best by this much")
      .Range(O::kUniquenessRatios)
      .Unit("%");
  DeclareParam("speckle_window", &options_.speckle_window,
               "blobs of fewer pixels with other disparities are dropped (0: off)")
      .Range(O::kSpeckleWindows)
      .Unit("px");
  DeclareParam("left_right_check", &options_.left_right_check,
               "match the mirrored pair too and keep the consistent pixels");
  DeclareParam("lr_max_diff_px", &options_.lr_max_diff_px, "largest |d_L - d_R| kept")
      .Range(O::kLrDiffs)
      .Unit("px");
  DeclareParam("once_per_rest", &once_per_rest_,
               "with joints connected: one depth each time the head comes to rest (else every "
               "step at rest)");
  DeclareParam("every_steps", &every_steps_, "without joints: a depth every this many steps")
      .Range(1, 1e6);
}

void DenseStereoComponent::Configured() { stereo_.emplace(options_); }

void DenseStereoComponent::Step(const runtime::StepContext& context) {
  const runtime::ImageMessage* l = left_.get();
  const runtime::ImageMessage* r = right_.get();
  if (l == nullptr || r == nullptr || !l->image || !r->image || !left_.fresh()) return;
  if (FrameOf(l->image) != FrameOf(r->image)) return;  // not a pair
  if (joints_.connected()) {
    const JointStateMessage* joints = joints_.get();
    if (joints == nullptr || !joints->arrived) {
      computed_this_rest_ = false;
      return;
    }
    // A new target the head was already at (no motion between) begins a rest too.
    if (!(joints->targets == rest_targets_)) computed_this_rest_ = false;
    if (once_per_rest_ && computed_this_rest_) return;
    rest_targets_ = joints->targets;
  } else if (context.step % every_steps_ != 0) {
    return;
  }
  const Image& left = *l->image;
  const Image& right = *r->image;
  auto stereo = std::make_shared<vision::StereoDepth>(
      stereo_->Compute({&left, vision::CameraModelOf(left), vision::CameraPoseOf(left)},
                       {&right, vision::CameraModelOf(right), vision::CameraPoseOf(right)}));
  computed_this_rest_ = true;
  DepthMessage out;
  out.time = context.time;
  out.frame_index = FrameOf(l->image);
  out.left = l->image;
  const Image& depth = stereo->depth;
  int64_t matched = 0;
  for (int v = 0; v < depth.height(); ++v) {
    const float* row = reinterpret_cast<const float*>(depth.data() + v * depth.stride());
    for (int u = 0; u < depth.width(); ++u) matched += row[u] > 0 ? 1 : 0;
  }
  out.matched = depth.width() * depth.height() > 0
                    ? static_cast<double>(matched) / (depth.width() * depth.height())
                    : 0.0;
  out.baseline_m = stereo->baseline_m;
  out.focal_px = stereo->focal_px;
  out.stereo = std::move(stereo);
  depth_.Emit(out);
}

// ---- mapping.world_map ----

WorldMapComponent::WorldMapComponent()
    : depth_(AddInput<DepthMessage>("depth", /*required=*/true)),
      selection_(AddInput<SelectionMessage>("selection")),
      candidates_(AddInput<CandidatesMessage>("candidates")),
      map_out_(AddOutput<MapMessage>("map")) {
  using O = mapping::WorldMap::Options;
  DeclareParam("resolution_m", &map_options_.resolution_m, "voxel edge")
      .Range(O::kResolutions)
      .Unit("m");
  DeclareParam("max_range_m", &map_options_.max_range_m, "depth beyond is not inserted")
      .Range(O::kRanges)
      .Unit("m");
  DeclareParam("stride", &map_options_.stride, "every stride-th row and column of the depth")
      .Range(O::kStrides);
  DeclareParam("min_confidence", &map_options_.min_confidence,
               "samples of lower confidence left out")
      .Range(O::kConfidences);
  DeclareParam("edge_ratio", &map_options_.edge_ratio,
               "samples whose neighbours differ by more than this share of their depth left out")
      .Range(O::kEdgeRatios);
  DeclareParam("hit_probability", &map_options_.hit_probability, "OctoMap's sensor model")
      .Range(O::kHits);
  DeclareParam("miss_probability", &map_options_.miss_probability, "OctoMap's sensor model")
      .Range(O::kMisses);
  DeclareParam("occupancy_threshold", &map_options_.occupancy_threshold,
               "occupied above it: 0.75 takes two hits, 0.5 one")
      .Range(O::kThresholds);
  using I = mapping::Inhibition3d::Options;
  ior_options_.time_constant_s = 10.0;
  ior_options_.radius_m = 0.3;
  DeclareParam("ior_time_constant_s", &ior_options_.time_constant_s,
               "a fixated place's inhibition decays as exp(-t / this)")
      .Range(I::kTimeConstants)
      .Unit("s");
  DeclareParam("ior_radius_m", &ior_options_.radius_m, "a fixated place inhibits this far")
      .Range(I::kRadii)
      .Unit("m");
  using T = mapping::PointTracker::Options;
  DeclareParam("track_gate_m", &track_options_.gate_m,
               "a face of `candidates` continues the track nearest it within this distance")
      .Range(T::kGates)
      .Unit("m");
  DeclareParam("track_lost_after_s", &track_options_.lost_after_s,
               "a face unseen this long is a new object when it comes back")
      .Range(T::kLostAfter)
      .Unit("s");
  DeclareParam("publish_every", &publish_every_, "the map is emitted after every this many depths")
      .Range(1, 1e6);
  DeclareParam("ply", &ply_, "write the final map here (PLY points, metres, world); \"\": none");
}

void WorldMapComponent::Configured() {
  map_ = std::make_shared<mapping::WorldMap>(map_options_);
  ior_.emplace(ior_options_);
  tracker_.emplace(track_options_);
}

void WorldMapComponent::Step(const runtime::StepContext& context) {
  // Faces move: the places anchored to one follow its track (mapping/point_tracker.h).
  const CandidatesMessage* faces = candidates_.get();
  if (faces != nullptr && candidates_.fresh()) {
    std::vector<Eigen::Vector3d> points;
    for (const FaceCandidate& face : faces->candidates) points.push_back(face.p_W);
    const std::vector<int> ids = tracker_->Update(points, context.time);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] >= 0) ior_->MoveObject(ids[i], Eigen::Isometry3d(Eigen::Translation3d(points[i])));
    }
  }
  const SelectionMessage* selection = selection_.get();
  if (selection != nullptr && selection_.fresh() && selection->valid && selection->fixating) {
    // A fixated face (a track seen now within the inhibited radius) holds its place on it.
    const auto face = tracker_->SeenNear(selection->p_W, ior_options_.radius_m);
    if (face) {
      ior_->Visit(selection->p_W, context.time, face->id,
                  Eigen::Isometry3d(Eigen::Translation3d(face->p_W)));
    } else {
      ior_->Visit(selection->p_W, context.time);
    }
  }
  const DepthMessage* depth = depth_.get();
  if (depth == nullptr || !depth_.fresh() || !depth->stereo) return;
  // The last map emitted stays as its readers saw it (copy on write).
  const auto start = std::chrono::steady_clock::now();
  if (map_.use_count() > 1) map_ = std::make_shared<mapping::WorldMap>(*map_);
  const auto copied = std::chrono::steady_clock::now();
  map_->Fuse(*depth->stereo);
  copy_ms_ += std::chrono::duration<double, std::milli>(copied - start).count();
  fuse_ms_ +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - copied).count();
  if (++fused_ % publish_every_ != 0) return;
  MapMessage out;
  out.time = context.time;
  out.frame_index = depth->frame_index;
  out.resolution_m = map_options_.resolution_m;
  out.occupied_W = map_->OccupiedCentres();
  out.fused = fused_;
  out.map = map_;
  out.ior = std::make_shared<const mapping::Inhibition3d>(*ior_);
  for (const mapping::Inhibition3d::Place& place : ior_->places()) {
    const double level = ior_->Level(place, context.time);
    if (level > 0) out.inhibited.push_back({place.p_W, ior_options_.radius_m, level});
  }
  std::stable_sort(
      out.inhibited.begin(), out.inhibited.end(),
      [](const InhibitedPlace& a, const InhibitedPlace& b) { return a.strength > b.strength; });
  map_out_.Emit(out);
}

void WorldMapComponent::Stop() {
  if (!map_) return;
  log::Info(
      "mapping.world_map '{}': {} depths fused, {} occupied voxels of {:g} m, {} places "
      "inhibited; fusion {:.0f} ms a depth, the readers' snapshot {:.0f} ms (wall clock)",
      name(), fused_, map_->occupied_voxels(), map_options_.resolution_m, ior_->places().size(),
      fuse_ms_ / std::max<int64_t>(fused_, 1), copy_ms_ / std::max<int64_t>(fused_, 1));
  if (ply_.empty()) return;
  map_->WritePly(ply_);
  log::Info("mapping.world_map '{}': the map is in {}", name(), ply_);
}

// ---- vision.explore ----

ExploreComponent::ExploreComponent()
    : image_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      joints_(AddInput<JointStateMessage>("joints", /*required=*/true)),
      depth_(AddInput<DepthMessage>("depth")),
      map_(AddInput<MapMessage>("map")),
      candidates_(AddInput<CandidatesMessage>("candidates")),
      target_out_(AddOutput<TargetMessage>("target")),
      selection_out_(AddOutput<SelectionMessage>("selection")) {
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("dwell_s", &dwell_s_, "time at rest on a target before the next is chosen")
      .Range(0.0, 1e6)
      .Unit("s");
  DeclareParam("settle_timeout_s", &settle_timeout_s_,
               "a target whose rest (and its depth) has not come this long after it was chosen "
               "is given up")
      .Range(Interval::LeftOpen(0.0, 1e6))
      .Unit("s");
  DeclareParam("saliency_weight", &attention_options_.saliency_weight,
               "weight of a zone's saliency in a candidate's score")
      .Range(0.0, 1e6);
  DeclareParam("novelty_weight", &attention_options_.novelty_weight,
               "weight of a candidate's novelty: with the map connected (in one process), the "
               "unknown space and once-seen surfaces its view's rays meet first; else the share "
               "of its view never looked at")
      .Range(0.0, 1e6);
  DeclareParam("tentative_value", &attention_options_.tentative_value,
               "novelty of a ray meeting a surface seen once (unknown space: 1)")
      .Range(0.0, 1e6);
  DeclareParam("turn_weight", &attention_options_.turn_weight,
               "score lost per radian of saccade (nearer targets first among equals)")
      .Range(0.0, 1e6);
  DeclareParam("target_distance_m", &attention_options_.target_distance_m,
               "a direction without a depth becomes a target this far from the head")
      .Range(0.1, 1e3)
      .Unit("m");
  DeclareParam("second_stage_faces", &attention_options_.second_stage_faces,
               "the second stage: search faces at full resolution in the best saliency zone");
  DeclareParam("face_weight", &attention_options_.face_weight,
               "a face found by the second stage scores this above its zone")
      .Range(0.0, 1e6);
  DeclareParam("grid_step", &grid_step_,
               "the head's reach is sampled every this many fields of view")
      .Range(Interval::LeftOpen(0.0, 2.0));
}

void ExploreComponent::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  scene_ = scene.scene;
  const head::HeadModel& head = internal::RobotOf(*scene_, scene.path).head;
  std::vector<Eigen::Vector3d> grid =
      ReachGrid(head, grid_step_ * EyeFieldOfView(head), attention_options_.target_distance_m);
  if (grid.empty()) {
    throw InvalidArgument(
        fmt::format("{}: the head of {} reaches no direction", name(), scene.path));
  }
  attention_.emplace(head, std::move(grid), attention_options_);
}

void ExploreComponent::Step(const runtime::StepContext& context) {
  const JointStateMessage* joints = joints_.get();
  if (joints == nullptr || image_.get() == nullptr) return;
  const head::HeadModel& head = scene_->robot()->head;
  if (target_W_) {
    // At rest on the target: the head arrived after this choice reached it (two steps: the
    // command, then the joints' delay).
    const bool at_rest = joints->arrived && context.step >= chosen_step_ + 2;
    if (!at_rest) {
      rest_since_.reset();
    } else if (!rest_since_) {
      rest_since_ = context.time;
      attention_->Looked(*target_W_);
    }
    const DepthMessage* depth = depth_.get();
    const bool depth_ready = !depth_.connected() || (depth != nullptr && rest_since_ &&
                                                     depth->time >= *rest_since_ - 1e-9);
    // A head that does not come to rest (or a rest without its depth) is given up after
    // settle_timeout_s: attention chooses again.
    const bool given_up = context.time - chosen_time_ >= settle_timeout_s_ - 1e-9;
    if (!given_up &&
        (!rest_since_ || context.time - *rest_since_ < dwell_s_ - 1e-9 || !depth_ready)) {
      Send(context, rest_since_.has_value());
      return;
    }
  }
  const std::optional<Eigen::Vector3d> next = Choose(context, head.Posture(joints->positions));
  if (next) {
    target_W_ = next;
    ++target_id_;
    chosen_step_ = context.step;
    chosen_time_ = context.time;
    rest_since_.reset();
  }
  Send(context, false);
}

std::optional<Eigen::Vector3d> ExploreComponent::Choose(const runtime::StepContext& context,
                                                        const Eigen::VectorXd& q) {
  const MapMessage* map = map_.get();
  const auto inhibition = [&](const Eigen::Vector3d& p_W) {
    double most = 0.0;
    if (map == nullptr) return most;
    if (map->ior) return map->ior->Inhibition(p_W, context.time);
    // A map from another process (DDS): its places at the strength they had when it was sent.
    for (const InhibitedPlace& place : map->inhibited) {
      if ((p_W - place.p_W).norm() <= place.radius_m) most = std::max(most, place.strength);
    }
    return most;
  };
  head::FixationSolver solver(scene_->robot()->head);
  const auto reachable = [&](const Eigen::Vector3d& p_W) {
    head::FixationOptions options;
    options.seed = q;
    options.axis_tolerance = 1e-4;
    return solver.Solve(p_W, options).reachable();
  };
  // The task first: the closest face that no place inhibits.
  if (const CandidatesMessage* faces = candidates_.get(); faces != nullptr) {
    for (const FaceCandidate& face : faces->candidates) {
      if (inhibition(face.p_W) < 0.5 && reachable(face.p_W)) {
        source_ = "explore_task";
        return face.p_W;
      }
    }
  }
  const DepthMessage* depth = depth_.get();
  const runtime::ImageMessage* image = image_.get();
  for (const ExploreCandidate& candidate :
       attention_->Rank(depth != nullptr ? depth->stereo.get() : nullptr,
                        image != nullptr ? image->image.get() : nullptr, inhibition,
                        map != nullptr ? map->map.get() : nullptr)) {
    if (!reachable(candidate.p_W)) continue;
    source_ = candidate.source == ExploreCandidate::Source::kFace       ? "explore_face"
              : candidate.source == ExploreCandidate::Source::kSaliency ? "explore_saliency"
                                                                        : "explore_reach";
    return candidate.p_W;
  }
  log::Warn("vision.explore '{}': step {}: no candidate is reachable", name(), context.step);
  return std::nullopt;
}

void ExploreComponent::Send(const runtime::StepContext& context, bool fixating) {
  if (!target_W_) return;
  const int64_t frame = FrameOf(image_.get()->image);
  TargetMessage target;
  target.time = context.time;
  target.frame_index = frame;
  target.valid = true;
  target.target_id = target_id_;
  target.p_W = *target_W_;
  target.source = source_;
  target_out_.Emit(target);
  SelectionMessage selection;
  selection.time = context.time;
  selection.frame_index = frame;
  selection.valid = true;
  selection.target_id = target_id_;
  selection.p_W = *target_W_;
  selection.fixating = fixating;
  selection.exploring = true;
  selection.dwell_s = fixating && rest_since_ ? context.time - *rest_since_ : 0.0;
  if (const MapMessage* map = map_.get(); map != nullptr) {
    for (const InhibitedPlace& place : map->inhibited) selection.suppressed_W.push_back(place.p_W);
  }
  selection_out_.Emit(selection);
}

}  // namespace saccade::components
