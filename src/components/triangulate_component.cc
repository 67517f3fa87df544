#include "saccade/components/triangulate_component.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "components/internal_frames.h"
#include "components/internal_scene.h"
#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {

using internal::Centre;
using internal::FrameOf;

TriangulateComponent::TriangulateComponent()
    : left_(AddInput<TrackMessage>("left", /*required=*/true)),
      right_(AddInput<TrackMessage>("right", /*required=*/true)),
      selection_(AddInput<SelectionMessage>("selection", /*required=*/true)),
      target_(AddOutput<TargetMessage>("target")) {
  DeclareParam("max_reprojection_px", &max_reprojection_px_,
               "largest reprojection error of the two tracks' triangulation")
      .Range(1e-6, 1e6)
      .Unit("px");
  DeclareParam("prefer", &prefer_,
               "detections: the tracks only bridge frames without one; tracks: always the tracks")
      .Choices({"detections", "tracks"});
}

void TriangulateComponent::Configured() { prefer_tracks_ = prefer_ == "tracks"; }

void TriangulateComponent::Step(const runtime::StepContext& context) {
  const SelectionMessage* selection = selection_.get();
  if (selection == nullptr || !selection_.fresh()) return;
  TargetMessage out;
  out.time = context.time;
  out.frame_index = selection->frame_index;
  out.target_id = selection->target_id;
  if (!selection->valid) {
    target_.Emit(out);
    return;
  }
  out.valid = true;
  out.p_W = selection->p_W;
  out.source = "selection";
  const TrackMessage* l = left_.get();
  const TrackMessage* r = right_.get();
  const bool tracks_usable = l != nullptr && r != nullptr && l->tracking && r->tracking &&
                             l->target_id == selection->target_id &&
                             r->target_id == selection->target_id && l->image && r->image &&
                             FrameOf(l->image) == FrameOf(r->image);
  std::optional<vision::StereoMatch> tracked;
  if (tracks_usable) {
    tracked = associator_.Triangulate(*l->image, vision::StereoObservation::FromBox(l->window),
                                      *r->image, vision::StereoObservation::FromBox(r->window));
    if (!tracked || !(tracked->reprojection_px <= max_reprojection_px_) ||
        !(tracked->depth_m > 0.0)) {
      tracked.reset();
    } else {
      track_points_.emplace_back(FrameOf(l->image), tracked->p_W);
      while (track_points_.size() > 64) track_points_.pop_front();
    }
  }
  // A detection of the target: its offset from the tracks' point in its own frame.
  if (selection->boxes_fresh) {
    offset_target_ = -1;
    for (const auto& [frame, p_W] : track_points_) {
      if (frame != selection->frame_index) continue;
      offset_ = selection->p_W - p_W;
      offset_target_ = selection->target_id;
    }
  }
  const bool detection_now =
      selection->boxes_fresh && (!tracked || selection->frame_index == FrameOf(l->image));
  // Without an offset for this target (the tracks started after the frame of its last
  // detection, as when a late detection reseeds them), the detection's point stands: the
  // tracks' own point can be centimetres off.
  const bool anchored = offset_target_ == selection->target_id;
  if (tracked && (prefer_tracks_ || (!detection_now && anchored))) {
    out.p_W = tracked->p_W;
    if (!prefer_tracks_) out.p_W += offset_;
    out.source = "tracks";
    out.reprojection_px = tracked->reprojection_px;
    out.gap_m = tracked->gap_m;
  }
  target_.Emit(out);
}

}  // namespace saccade::components
