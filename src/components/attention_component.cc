#include "saccade/components/attention_component.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "components/internal_frames.h"
#include "components/internal_scene.h"
#include "saccade/core/error.h"
#include "saccade/head/fixation.h"
#include "saccade/head/kinematics.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {

using internal::Centre;
using internal::FrameOf;

AttentionComponent::AttentionComponent()
    : candidates_(AddInput<CandidatesMessage>("candidates", /*required=*/true)),
      joints_(AddInput<JointStateMessage>("joints")),
      selection_(AddOutput<SelectionMessage>("selection")) {
  AddMethod<runtime::Empty, runtime::Text>(
      "reset",
      [this](const runtime::Empty&) {
        const std::size_t n = ior_ ? ior_->suppressions().size() : 0;
        ior_.emplace(ior_options_);
        current_ = SelectionMessage{};
        return runtime::Text{"forgot the target and " + std::to_string(n) + " suppressed places"};
      },
      "forgets the target and what inhibition of return suppresses: every face is new again");
  ior_options_.suppression_time_s = 60.0;  // a minute: the demo's faces are not seen twice
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("fixation_time_s", &ior_options_.fixation_time_s,
               "dwell on a face before it is suppressed")
      .Range(vision::InhibitionOfReturn::Options::kDwells)
      .Unit("s");
  DeclareParam("radius_m", &ior_options_.radius_m, "size of a fixated or suppressed place")
      .Range(vision::InhibitionOfReturn::Options::kRadii)
      .Unit("m");
  DeclareParam("follow_objects", &ior_options_.follow,
               "suppressed places and the dwell follow the faces as they move");
  DeclareParam("suppression_time_s", &ior_options_.suppression_time_s,
               "how long a fixated place stays suppressed")
      .Range(vision::InhibitionOfReturn::Options::kSuppressions)
      .Unit("s");
  DeclareParam("lost_after_s", &lost_after_s_, "a target unseen this long is dropped")
      .Range(0.0, 1e6)
      .Unit("s");
  DeclareParam("fixation_tolerance_m", &fixation_tolerance_m_,
               "the head fixates a target when its fixation point is this close")
      .Range(1e-6, 1e6)
      .Unit("m");
  DeclareParam("onset_tolerance_deg", &onset_tolerance_deg_,
               "a fixation begins once the target, as this step's images put it, is this close to "
               "where the eyes point, seen from the head (180: as soon as the head arrives)")
      .Range(0.0, 180.0)
      .Unit("deg");
  DeclareParam("explore_after_s", &explore_after_s_,
               "with nothing to look at this long, the head goes home")
      .Range(0.0, 1e6)
      .Unit("s");
  DeclareParam("home_distance_m", &home_distance_m_,
               "home: a point this far straight ahead of the head's base")
      .Range(0.1, 1e3)
      .Unit("m");
}

void AttentionComponent::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  ior_.emplace(ior_options_);
  scene_ = scene.scene;
  internal::RobotOf(*scene_, scene.path);
}

void AttentionComponent::Step(const runtime::StepContext& context) {
  const head::HeadModel& head = scene_->robot()->head;
  const head::JointState joints =
      joints_.has_value() ? joints_.value().positions : scene_->robot()->initial_joints;
  // The viewer: midway between the optical centres (POPEYE's cyclopean point).
  const std::array<geometry::Pose, 2> cameras = head.CameraPoses(joints);
  const Eigen::Vector3d viewer = 0.5 * (cameras[0].translation() + cameras[1].translation());
  const std::optional<Eigen::Vector3d> p_WFixation = head::FixationPoint(cameras[0], cameras[1]);

  std::vector<Eigen::Vector3d> points;
  const CandidatesMessage* candidates = candidates_.fresh() ? &candidates_.value() : nullptr;
  if (candidates != nullptr) {
    for (const FaceCandidate& c : candidates->candidates) points.push_back(c.p_W);
  }

  // The candidate that is the current target: the nearest within radius_m of it.
  std::optional<std::size_t> same;
  if (current_.valid) {
    double best = ior_options_.radius_m;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double d = (points[i] - current_.p_W).norm();
      if (d <= best) {
        best = d;
        same = i;
      }
    }
  }

  // The head fixates the target when it is at rest with its fixation point on it. A fixation
  // begins only where this step's sighting of the target agrees with where the eyes point
  // (onset_tolerance_deg, seen from the head): a saccade lands where the sightings during it
  // put the target, and the first sharp image may call for a corrective one.
  bool fixating = false;
  if (current_.valid && !current_.exploring && joints_.has_value() && joints_.value().arrived &&
      p_WFixation) {
    fixating = (*p_WFixation - current_.p_W).norm() <= fixation_tolerance_m_;
    if (fixating && !current_.fixating) {
      const Eigen::Vector3d to_fixation = *p_WFixation - viewer;
      fixating = same.has_value() && std::atan2(to_fixation.cross(points[*same] - viewer).norm(),
                                                to_fixation.dot(points[*same] - viewer)) <=
                                         onset_tolerance_deg_ * M_PI / 180.0;
    }
  }
  const std::optional<std::size_t> closest =
      ior_->Select(context.time, points, viewer,
                   fixating ? std::optional<Eigen::Vector3d>(current_.p_W) : std::nullopt);

  SelectionMessage out = current_;
  out.time = context.time;
  out.frame_index = candidates != nullptr ? candidates->frame_index : context.step;
  out.boxes_fresh = false;
  const bool keep = current_.valid && !current_.exploring &&
                    !ior_->IsSuppressed(current_.p_W, context.time) &&
                    (same || context.time - last_seen_ <= lost_after_s_);
  std::optional<std::size_t> chosen;
  if (keep) {
    chosen = same;
  } else if (closest) {
    chosen = closest;
    out.target_id = next_id_++;  // attention moves to another place
    out.exploring = false;
    fixating = false;
  } else if (!current_.exploring) {
    // Nothing to look at: after a while, look around from home.
    if (current_.valid) idle_since_ = context.time;
    out.valid = false;
    if (context.time - idle_since_ >= explore_after_s_) {
      out.valid = true;
      out.exploring = true;
      out.target_id = next_id_++;
      fixating = false;  // home is not a face
      out.p_W = head.X_WB() * Eigen::Vector3d(home_distance_m_, 0.0, 0.0);
    }
  }
  if (chosen) {
    const FaceCandidate& c = candidates->candidates[*chosen];
    out.valid = true;
    out.p_W = c.p_W;
    out.boxes_fresh = true;
    out.left_box = c.left_box;
    out.right_box = c.right_box;
    last_seen_ = context.time;
  }
  out.fixating = out.valid && fixating;
  out.dwell_s = out.fixating ? ior_->dwell_s() : 0.0;
  out.suppressed_W.clear();
  for (const vision::InhibitionOfReturn::Suppression& s : ior_->suppressions()) {
    out.suppressed_W.push_back(s.p_W);
  }
  current_ = out;
  selection_.Emit(out);
}

}  // namespace saccade::components
