#include "saccade/components/camshift_component.h"

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

CamShiftComponent::CamShiftComponent()
    : image_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      selection_(AddInput<SelectionMessage>("selection", /*required=*/true)),
      track_(AddOutput<TrackMessage>("track")) {
  DeclareParam("eye", &eye_, "the eye whose image and box it tracks")
      .Choices({"left", "right"})
      .Required();
  DeclareParam("min_mass_ratio", &options_.min_mass_ratio,
               "the track is lost when the window's hue mass falls below this share of the seed's")
      .Range(vision::CamShiftTracker::Options::kMassRatios);
  DeclareParam("history_frames", &history_frames_,
               "images kept for detections that arrive late: one older than this is not used")
      .Range(1, 64);
  DeclareParam("reseed_fraction", &reseed_fraction_,
               "re-seed when a detection lies farther than this share of its width from the track")
      .Range(0.0, 100.0);
}

void CamShiftComponent::Configured() {
  left_ = eye_ == "left";
  tracker_ = std::make_unique<vision::CamShiftTracker>(options_);
}

bool CamShiftComponent::StartAndCatchUp(std::size_t from, const cv::Rect& box) {
  if (!tracker_->Start(*recent_[from].image, box)) return false;
  recent_[from].centre = tracker_->state().Center();
  for (std::size_t k = from + 1; k < recent_.size(); ++k) {
    const vision::TrackState state = tracker_->Update(*recent_[k].image);
    if (state.lost()) return false;
    recent_[k].centre = state.Center();
  }
  return true;
}

void CamShiftComponent::Step(const runtime::StepContext&) {
  if (!image_.fresh() || !image_.value().image) return;
  const std::shared_ptr<const Image>& image = image_.value().image;
  recent_.push_back({image, std::nullopt});
  while (recent_.size() > static_cast<std::size_t>(history_frames_)) recent_.pop_front();
  const std::size_t now = recent_.size() - 1;
  TrackMessage out;
  out.image = image;
  const SelectionMessage* selection = selection_.get();
  if (selection == nullptr || !selection->valid || selection->exploring) {
    // Nothing to follow: no target, or the home point that attention looks at while it
    // explores (not a face: no boxes).
    target_id_ = -1;
    out.reason = selection != nullptr && selection->valid ? "exploring: no face" : "no target";
    track_.Emit(out);
    return;
  }
  const cv::Rect box = left_ ? selection->left_box : selection->right_box;
  // The image the selection's boxes were found in: this one, or a recent one (a detection
  // that arrived late).
  std::optional<std::size_t> found;
  if (selection->boxes_fresh) {
    for (std::size_t k = 0; k < recent_.size(); ++k) {
      if (recent_[k].image->metadata().frame_index == selection->frame_index) found = k;
    }
  }
  const bool detected = found.has_value();
  const bool same_target = selection->target_id == target_id_ && tracker_->tracking();
  if (same_target) {
    const vision::TrackState state = tracker_->Update(*image);
    if (!state.lost()) recent_[now].centre = state.Center();
    // A detection of the target far from where the track was in its image means the track
    // drifted: start again.
    const std::optional<cv::Point2d>& then = detected ? recent_[*found].centre : std::nullopt;
    const bool drifted = detected && !state.lost() && then &&
                         cv::norm(*then - Centre(box)) > reseed_fraction_ * box.width;
    if ((state.lost() || drifted) && detected) {
      out.reseeded = StartAndCatchUp(*found, box);
    } else if (state.lost()) {
      out.reason = state.reason;
    }
  } else if (detected) {
    out.reseeded = StartAndCatchUp(*found, box);
    if (!out.reseeded) out.reason = "the detection holds no usable colour";
  } else {
    // A new target and no detection of it yet: the last target's track does not follow it.
    if (tracker_->tracking()) tracker_ = std::make_unique<vision::CamShiftTracker>(options_);
    out.reason = "waiting for a detection of the target";
  }
  out.target_id = selection->target_id;
  target_id_ = tracker_->tracking() ? selection->target_id : -1;
  out.tracking = tracker_->tracking();
  if (out.tracking) {
    out.window = tracker_->state().window;
    out.center = tracker_->state().Center();
  }
  track_.Emit(out);
}

}  // namespace saccade::components
