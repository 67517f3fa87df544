#include "saccade/components/stereo_faces_component.h"

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
using Options = vision::StereoAssociator::Options;

StereoFacesComponent::StereoFacesComponent()
    : left_(AddInput<FacesMessage>("left", /*required=*/true)),
      right_(AddInput<FacesMessage>("right", /*required=*/true)),
      candidates_(AddOutput<CandidatesMessage>("candidates")) {
  // A human face's width as the cascade boxes it (the library accepts any width).
  options_.min_width_m = 0.08;
  options_.max_width_m = 0.4;
  options_.refine_disparity = true;
  DeclareParam("refine_disparity", &options_.refine_disparity,
               "match each pair's left face patch in the right image (sub-pixel) for its depth");
  DeclareParam("max_reprojection_px", &options_.max_reprojection_px,
               "largest reprojection error of a left/right pair")
      .Range(Options::kReprojections)
      .Unit("px");
  DeclareParam("min_depth_m", &options_.min_depth_m, "nearest depth of a pair")
      .Range(Options::kDepths)
      .Unit("m");
  DeclareParam("max_depth_m", &options_.max_depth_m,
               "farthest depth of a pair; more than min_depth_m")
      .Range(Options::kDepths)
      .Unit("m");
  DeclareParam("min_width_m", &options_.min_width_m,
               "narrowest face; 0 with max_width_m 0: no width check")
      .Range(Options::kWidths)
      .Unit("m");
  DeclareParam("max_width_m", &options_.max_width_m,
               "widest face; more than min_width_m, or 0 with min_width_m 0: no width check")
      .Range(Options::kWidths)
      .Unit("m");
}

void StereoFacesComponent::Configured() {
  associator_ = vision::StereoAssociator(options_);  // throws with IsValid's message
}

void StereoFacesComponent::Step(const runtime::StepContext& context) {
  if (!left_.has_value() || !right_.has_value()) return;
  if (!left_.fresh() && !right_.fresh()) return;
  const FacesMessage& left = left_.value();
  const FacesMessage& right = right_.value();
  // Only a pair taken at the same moment can be triangulated.
  if (!left.image || !right.image || FrameOf(left.image) != FrameOf(right.image)) return;
  std::vector<vision::StereoObservation> l, r;
  std::vector<cv::Rect> l_boxes, r_boxes;
  for (const FacesMessage::Face& f : left.faces) {
    if (f.rejected) continue;
    l.push_back(vision::StereoObservation::FromBox(f.box));
    l_boxes.push_back(f.box);
  }
  for (const FacesMessage::Face& f : right.faces) {
    if (f.rejected) continue;
    r.push_back(vision::StereoObservation::FromBox(f.box));
    r_boxes.push_back(f.box);
  }
  CandidatesMessage out;
  out.time = context.time;
  out.frame_index = FrameOf(left.image);
  for (const vision::StereoMatch& m : associator_.Associate(*left.image, l, *right.image, r)) {
    out.candidates.push_back({m.p_W, l_boxes[m.left], r_boxes[m.right], m.distance_m,
                              m.reprojection_px, m.gap_m, m.width_m});
  }
  candidates_.Emit(out);
}

}  // namespace saccade::components
