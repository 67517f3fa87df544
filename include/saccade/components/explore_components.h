#pragma once
// Exploration and mapping as pipeline components (seed 7.2, issue 44): the same parts as
// `saccade explore`, in a loop of the pipeline's clock, on simulated, recorded (`saccade run
// --play`) or live cameras, without ground truth. pipelines/explore.yaml connects them:
//
//   cameras.left/right -> vision.dense_stereo -> mapping.world_map -> (map, delay 1)
//        |                      | depth                     ^ selection        |
//        +--> vision.explore <--+---------------------------+------------------+
//                  | target -> control.fixation -> head
//
// vision.dense_stereo -- dense stereo depth of the eye pair (vision/dense_stereo.h): the pair
//   rectified from the images' calibration and pose, matched by SGBM with a left-right check.
//   With `joints` connected it computes only while the head is at rest (no motion blur), once
//   per rest (`once_per_rest`: a rest begins when the head arrives, or is given new targets
//   where it already is); without, every `every_steps` steps.
//   inputs: left, right (image, required), joints (head.joints)
//   outputs: depth (vision.depth)
//
// mapping.world_map -- the occupancy map (mapping/world_map.h, OctoMap) of every depth, and
//   the places inhibition of return holds (mapping/inhibition_3d.h), world-anchored and
//   decaying: each place a `selection` fixates; a place on a face of `candidates` (a face
//   pipeline's triangulated faces) is anchored to that face's track (mapping/point_tracker.h)
//   and moves with it. Emits the map (occupied voxels' centres and the places; in one process
//   the map itself and the inhibition too, as snapshots) after every `publish_every` depths
//   fused; writes it as PLY (`ply`) at the end.
//   inputs: depth (vision.depth, required), selection (vision.selection),
//           candidates (vision.candidates)
//   outputs: map (mapping.map)
//
// vision.explore -- two-stage attention for exploration (components/explore_attention.h): at
//   rest on a target for dwell_s (and, with `depth` connected, once this rest's depth came),
//   it ranks the saliency zones of the left image and the head's reach by saliency, novelty
//   and the map's inhibition of return, and sends the head to the best reachable one. Novelty
//   is the map's (RayNovelty: unknown space and surfaces seen once that the candidate view's
//   rays meet first) when the map comes from this process; a map from DDS carries no free or
//   unknown space, and novelty is then the share of the view never looked at. The
//   second stage (second_stage_faces, on by default) searches faces at full resolution in the
//   best zone only; a face found there comes first. With `candidates` connected (a face
//   pipeline's), the closest face no place inhibits comes before all (the task). The target's
//   source says which: explore_task, explore_face, explore_saliency or explore_reach. A target
//   whose rest (and its depth) has not come settle_timeout_s after it was chosen is given up.
//   inputs: image (image, required: the left eye's), joints (head.joints, required),
//           depth (vision.depth), map (mapping.map), candidates (vision.candidates)
//   outputs: target (vision.target), selection (vision.selection: fixating while at rest on
//            the target; the map's places as suppressed_W)
// Parameters: declared in the constructors (docs/components.md lists them).
#include <memory>
#include <optional>
#include <string>

#include "saccade/components/explore_attention.h"
#include "saccade/components/messages.h"
#include "saccade/mapping/inhibition_3d.h"
#include "saccade/mapping/point_tracker.h"
#include "saccade/mapping/world_map.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/dense_stereo.h"

namespace saccade::components {

class DenseStereoComponent : public runtime::Component {
 public:
  DenseStereoComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  runtime::Input<runtime::ImageMessage>& left_;
  runtime::Input<runtime::ImageMessage>& right_;
  runtime::Input<JointStateMessage>& joints_;
  runtime::Output<DepthMessage>& depth_;
  vision::DenseStereo::Options options_;
  std::optional<vision::DenseStereo> stereo_;
  bool once_per_rest_ = true;
  int every_steps_ = 5;
  bool computed_this_rest_ = false;
  head::JointState rest_targets_;  // the targets of the rest computed
};

class WorldMapComponent : public runtime::Component {
 public:
  WorldMapComponent();
  void Step(const runtime::StepContext& context) override;
  void Stop() override;

 protected:
  void Configured() override;

 private:
  runtime::Input<DepthMessage>& depth_;
  runtime::Input<SelectionMessage>& selection_;
  runtime::Input<CandidatesMessage>& candidates_;
  runtime::Output<MapMessage>& map_out_;
  mapping::WorldMap::Options map_options_;
  mapping::Inhibition3d::Options ior_options_;
  mapping::PointTracker::Options track_options_;
  // Shared with the readers of the last map emitted: copied before a fusion while they hold it.
  std::shared_ptr<mapping::WorldMap> map_;
  std::optional<mapping::Inhibition3d> ior_;
  std::optional<mapping::PointTracker> tracker_;
  int publish_every_ = 1;
  std::string ply_;
  int64_t fused_ = 0;
  double fuse_ms_ = 0.0, copy_ms_ = 0.0;  // wall clock, for the log at Stop
};

class ExploreComponent : public runtime::Component {
 public:
  ExploreComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  std::optional<Eigen::Vector3d> Choose(const runtime::StepContext& context,
                                        const Eigen::VectorXd& q);
  void Send(const runtime::StepContext& context, bool fixating);

  std::string scene_param_;
  runtime::Input<runtime::ImageMessage>& image_;
  runtime::Input<JointStateMessage>& joints_;
  runtime::Input<DepthMessage>& depth_;
  runtime::Input<MapMessage>& map_;
  runtime::Input<CandidatesMessage>& candidates_;
  runtime::Output<TargetMessage>& target_out_;
  runtime::Output<SelectionMessage>& selection_out_;
  std::shared_ptr<const scene::Scene> scene_;
  ExploreAttention::Options attention_options_ = [] {
    ExploreAttention::Options o;
    o.second_stage_faces = true;
    return o;
  }();
  std::optional<ExploreAttention> attention_;
  double grid_step_ = 0.375;  // fields of view
  double dwell_s_ = 0.2;
  // The target: where, its id, when the head came to rest on it (nullopt: moving).
  std::optional<Eigen::Vector3d> target_W_;
  int64_t target_id_ = -1;
  int64_t chosen_step_ = 0;
  double chosen_time_ = 0.0;
  double settle_timeout_s_ = 3.0;
  std::optional<double> rest_since_;
  std::string source_;  // what proposed the target: explore_face, _saliency, _reach, _task
};

}  // namespace saccade::components
