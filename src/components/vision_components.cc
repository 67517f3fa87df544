#include "saccade/components/vision_components.h"

#include <cmath>
#include <span>
#include <vector>

#include "components/internal_scene.h"
#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {
namespace {

cv::Point2d Centre(const cv::Rect& box) {
  return {box.x + (box.width - 1) / 2.0, box.y + (box.height - 1) / 2.0};
}

int64_t FrameOf(const std::shared_ptr<const Image>& image) {
  return image ? image->metadata().frame_index : -1;
}

}  // namespace

// ---- pre-processing ----------------------------------------------------------------------

ImageFilterComponent::ImageFilterComponent()
    : in_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      out_(AddOutput<runtime::ImageMessage>("image")) {}

void ImageFilterComponent::Step(const runtime::StepContext&) {
  if (!in_.fresh() || !in_.value().image) return;
  out_.Emit(runtime::ImageMessage{std::make_shared<const Image>(Apply(*in_.value().image))});
}

UndistortComponent::UndistortComponent() {
  DeclareParam("bilinear", &options_.bilinear, "bilinear interpolation (else nearest pixel)");
  DeclareParam("border_value", &options_.border_value,
               "grey level of the pixels that no source pixel maps to")
      .Range(0, 255);
}

Image UndistortComponent::Apply(const Image& image) {
  // The maps are made once per camera; a camera whose model changes gets new ones.
  const geometry::CameraModel camera = vision::CameraModelOf(image);
  if (!undistorter_ || !(undistorter_->camera() == camera)) {
    undistorter_ = std::make_unique<vision::Undistorter>(camera, options_);
  }
  return undistorter_->Apply(image);
}

MedianComponent::MedianComponent() {
  DeclareParam("kernel_size", &options_.kernel_size, "side of the square window, odd")
      .Range(3, 255)
      .Unit("px");
}

void MedianComponent::Configured() { filter_ = vision::MedianFilter(options_); }

SharpenComponent::SharpenComponent() {
  DeclareParam("amount", &options_.amount, "weight of the detail added back (unsharp mask)")
      .Range(0.0, 100.0);
  DeclareParam("sigma", &options_.sigma, "Gaussian blur whose difference is the detail")
      .Range(1e-6, 50.0)
      .Unit("px");
}

void SharpenComponent::Configured() { filter_ = vision::Sharpener(options_); }

// ---- detection -----------------------------------------------------------------------------

FaceDetectorComponent::FaceDetectorComponent()
    : image_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      faces_(AddOutput<FacesMessage>("faces")) {
  DeclareParam("min_neighbors", &options_.min_neighbors, "overlapping hits needed to keep a box")
      .Range(0, 1000);
  DeclareParam("scale_factor", &options_.scale_factor, "size step between pyramid levels")
      .Range(1.0001, 4.0);
  DeclareParam("min_size_px", &options_.min_size_px, "smallest face side")
      .Range(1, 100000)
      .Unit("px");
  DeclareParam("max_size_px", &options_.max_size_px, "largest face side; 0: no limit")
      .Range(0, 100000)
      .Unit("px");
  DeclareParam("reject_cats", &reject_cats_, "reject boxes that the cat-face cascade also finds");
  DeclareParam("require_eyes", &require_eyes_, "reject boxes without an eye inside");
}

void FaceDetectorComponent::Configured() {
  vision::FaceDetector::Options options = options_;
  if (!reject_cats_) options.cat_cascade_path = "";
  if (!require_eyes_) options.eye_cascade_path = "";
  detector_ = std::make_unique<vision::FaceDetector>(options);
}

void FaceDetectorComponent::Step(const runtime::StepContext&) {
  if (!image_.fresh() || !image_.value().image) return;
  FacesMessage out;
  out.image = image_.value().image;
  for (const vision::FaceDetection& d : detector_->Detect(*out.image)) {
    out.faces.push_back({d.box, d.neighbors, d.rejected, d.reason});
  }
  faces_.Emit(out);
}

// ---- stereo --------------------------------------------------------------------------------

StereoFacesComponent::StereoFacesComponent()
    : left_(AddInput<FacesMessage>("left", /*required=*/true)),
      right_(AddInput<FacesMessage>("right", /*required=*/true)),
      candidates_(AddOutput<CandidatesMessage>("candidates")) {
  // A human face's width as the cascade boxes it (the library accepts any width).
  options_.min_width_m = 0.08;
  options_.max_width_m = 0.4;
  DeclareParam("max_reprojection_px", &options_.max_reprojection_px,
               "largest reprojection error of a left/right pair")
      .Range(1e-6, 1e6)
      .Unit("px");
  DeclareParam("min_depth_m", &options_.min_depth_m, "nearest depth of a pair")
      .Range(1e-6, 1e6)
      .Unit("m");
  DeclareParam("max_depth_m", &options_.max_depth_m, "farthest depth of a pair")
      .Range(1e-6, 1e6)
      .Unit("m");
  DeclareParam("min_width_m", &options_.min_width_m, "narrowest face; 0: no limit")
      .Range(0.0, 1e6)
      .Unit("m");
  DeclareParam("max_width_m", &options_.max_width_m, "widest face; 0: no limit")
      .Range(0.0, 1e6)
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

// ---- attention -----------------------------------------------------------------------------

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
      .Range(1e-6, 1e6)
      .Unit("s");
  DeclareParam("radius_m", &ior_options_.radius_m, "size of a fixated or suppressed place")
      .Range(1e-6, 1e6)
      .Unit("m");
  DeclareParam("suppression_time_s", &ior_options_.suppression_time_s,
               "how long a fixated place stays suppressed")
      .Range(1e-6, 1e9)
      .Unit("s");
  DeclareParam("lost_after_s", &lost_after_s_, "a target unseen this long is dropped")
      .Range(0.0, 1e6)
      .Unit("s");
  DeclareParam("fixation_tolerance_m", &fixation_tolerance_m_,
               "the head fixates a target when its fixation point is this close")
      .Range(1e-6, 1e6)
      .Unit("m");
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
  const head::HeadDescription& head = scene_->robot()->head;
  const head::JointState joints =
      joints_.has_value() ? joints_.value().positions : scene_->robot()->initial_joints;
  const head::HeadFrames frames = head::ForwardKinematics(head, joints);
  const Eigen::Vector3d viewer = frames.X_WC.translation();

  // The head fixates the target when it is at rest with its fixation point on it.
  bool fixating = false;
  if (current_.valid && !current_.exploring && joints_.has_value() && joints_.value().arrived &&
      frames.p_WFixation) {
    fixating = (*frames.p_WFixation - current_.p_W).norm() <= fixation_tolerance_m_;
  }

  std::vector<Eigen::Vector3d> points;
  const CandidatesMessage* candidates = candidates_.fresh() ? &candidates_.value() : nullptr;
  if (candidates != nullptr) {
    for (const FaceCandidate& c : candidates->candidates) points.push_back(c.p_W);
  }
  const std::optional<std::size_t> closest =
      ior_->Select(context.time, points, viewer,
                   fixating ? std::optional<Eigen::Vector3d>(current_.p_W) : std::nullopt);

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
      out.p_W = frames.X_WB * Eigen::Vector3d(home_distance_m_, 0.0, 0.0);
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

// ---- tracking ------------------------------------------------------------------------------

CamShiftComponent::CamShiftComponent()
    : image_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      selection_(AddInput<SelectionMessage>("selection", /*required=*/true)),
      track_(AddOutput<TrackMessage>("track")) {
  DeclareParam("eye", &eye_, "the eye whose image and box it tracks")
      .Choices({"left", "right"})
      .Required();
  DeclareParam("min_mass_ratio", &options_.min_mass_ratio,
               "the track is lost when the window's hue mass falls below this share of the seed's")
      .Range(0.0, 0.999);
  DeclareParam("reseed_fraction", &reseed_fraction_,
               "re-seed when a detection lies farther than this share of its width from the track")
      .Range(0.0, 100.0);
}

void CamShiftComponent::Configured() {
  left_ = eye_ == "left";
  tracker_ = std::make_unique<vision::CamShiftTracker>(options_);
}

void CamShiftComponent::Step(const runtime::StepContext&) {
  if (!image_.fresh() || !image_.value().image) return;
  const std::shared_ptr<const Image>& image = image_.value().image;
  TrackMessage out;
  out.image = image;
  const SelectionMessage* selection = selection_.get();
  if (selection == nullptr || !selection->valid) {
    target_id_ = -1;
    out.reason = "no target";
    track_.Emit(out);
    return;
  }
  const cv::Rect box = left_ ? selection->left_box : selection->right_box;
  const bool detected =
      selection->boxes_fresh && selection->frame_index == image->metadata().frame_index;
  const bool same_target = selection->target_id == target_id_ && tracker_->tracking();
  if (same_target) {
    const vision::TrackState state = tracker_->Update(*image);
    // A detection of the target far from the track means the track drifted: start again.
    const bool drifted = detected && !state.lost() &&
                         cv::norm(state.Center() - Centre(box)) > reseed_fraction_ * box.width;
    if ((state.lost() || drifted) && detected) {
      out.reseeded = tracker_->Start(*image, box);
    } else if (state.lost()) {
      out.reason = state.reason;
    }
  } else if (detected) {
    out.reseeded = tracker_->Start(*image, box);
    if (!out.reseeded) out.reason = "the detection holds no usable colour";
  } else {
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

// ---- triangulation -------------------------------------------------------------------------

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
