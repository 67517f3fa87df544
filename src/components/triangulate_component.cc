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
                             FrameOf(l->image) == FrameOf(r->image) &&
                             FrameOf(l->image) == selection->frame_index;
  if (tracks_usable && (prefer_tracks_ || !selection->boxes_fresh)) {
    const auto match =
        associator_.Triangulate(*l->image, vision::StereoObservation::FromBox(l->window), *r->image,
                                vision::StereoObservation::FromBox(r->window));
    if (match && match->reprojection_px <= max_reprojection_px_ && match->depth_m > 0.0) {
      out.p_W = match->p_W;
      out.source = "tracks";
      out.reprojection_px = match->reprojection_px;
      out.gap_m = match->gap_m;
    }
  }
  target_.Emit(out);
}

}  // namespace saccade::components
