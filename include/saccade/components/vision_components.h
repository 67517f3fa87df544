#pragma once
// Perception as pipeline components (seed Fig. 2, middle block; section 5.2: featuresHaar,
// camshiftTracking, triangulation). Each wraps a class of `vision` and documents its ports;
// each declares its parameters in its constructor (docs/components.md is printed from them).
//
// vision.undistort / vision.median / vision.sharpen -- pre-processing (seed Fig. 2).
//   inputs: image (runtime.image, required); outputs: image (runtime.image), a new image with
//   the same metadata (undistort: distortion "none").
//
// vision.face_detector -- Haar faces with the cat and eye checks (vision/face_detector.h).
//   inputs: image (runtime.image, required); outputs: faces (vision.faces), every new image.
//
// vision.stereo_faces -- associates the left and right faces and triangulates them (seed 4.2).
//   inputs: left, right (vision.faces, required); outputs: candidates (vision.candidates)
//
// vision.attention -- chooses the face to look at: the closest one that inhibition of return
//   (seed 7.2) does not suppress; sticks to it until it has been fixated for fixation_time_s
//   (then it is suppressed for suppression_time_s) or unseen for lost_after_s. With nothing to
//   look at for explore_after_s, it sends the head home (a point home_distance_m straight
//   ahead of its base), from where it looks for faces again.
//   inputs: candidates (vision.candidates, required), joints (head.joints, delay 1)
//   outputs: selection (vision.selection)
//   methods: reset (runtime.empty -> runtime.text): forgets the target and every suppressed
//            place, so that every face is new again.
//
// vision.camshift -- one eye's CamShift track of the selected face (vision/camshift_tracker.h),
//   seeded by its detection box, re-seeded when a detection of the same target lies farther
//   than reseed_fraction of its width from the track, re-detected when lost.
//   inputs: image (runtime.image, required), selection (vision.selection, required)
//   outputs: track (vision.track)
//
// vision.triangulate -- the 3D target: the selection's point (triangulated detections) when
//   this frame's detections found the target, else the two eyes' CamShift tracks triangulated
//   (they bridge the frames the detector misses: motion blur, perspective), else the
//   selection's last point. `prefer: tracks` uses the tracks even when detections exist:
//   measured on the portraits, CamShift's window slides down onto the neck's skin, 22 mm
//   off the face centre at 2.2 m against 4 mm for the detections.
//   inputs: left, right (vision.track, required), selection (vision.selection, required)
//   outputs: target (vision.target)
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/camshift_tracker.h"
#include "saccade/vision/face_detector.h"
#include "saccade/vision/inhibition_of_return.h"
#include "saccade/vision/median_filter.h"
#include "saccade/vision/sharpener.h"
#include "saccade/vision/stereo_associator.h"
#include "saccade/vision/undistorter.h"

namespace saccade::components {

/// Base of the image-to-image pre-processing components.
class ImageFilterComponent : public runtime::Component {
 public:
  ImageFilterComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  virtual Image Apply(const Image& image) = 0;

 private:
  runtime::Input<runtime::ImageMessage>& in_;
  runtime::Output<runtime::ImageMessage>& out_;
};

class UndistortComponent : public ImageFilterComponent {
 public:
  UndistortComponent();

 protected:
  Image Apply(const Image& image) override;

 private:
  vision::Undistorter::Options options_;
  std::unique_ptr<vision::Undistorter> undistorter_;  // made for the latest camera seen
};

class MedianComponent : public ImageFilterComponent {
 public:
  MedianComponent();

 protected:
  void Configured() override;
  Image Apply(const Image& image) override { return filter_.Apply(image); }

 private:
  vision::MedianFilter::Options options_;
  vision::MedianFilter filter_;
};

class SharpenComponent : public ImageFilterComponent {
 public:
  SharpenComponent();

 protected:
  void Configured() override;
  Image Apply(const Image& image) override { return filter_.Apply(image); }

 private:
  vision::Sharpener::Options options_;
  vision::Sharpener filter_;
};

class FaceDetectorComponent : public runtime::Component {
 public:
  FaceDetectorComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  vision::FaceDetector::Options options_;
  bool reject_cats_ = true;
  bool require_eyes_ = true;
  runtime::Input<runtime::ImageMessage>& image_;
  runtime::Output<FacesMessage>& faces_;
  std::unique_ptr<vision::FaceDetector> detector_;
};

class StereoFacesComponent : public runtime::Component {
 public:
  StereoFacesComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  vision::StereoAssociator::Options options_;
  runtime::Input<FacesMessage>& left_;
  runtime::Input<FacesMessage>& right_;
  runtime::Output<CandidatesMessage>& candidates_;
  vision::StereoAssociator associator_;
};

class AttentionComponent : public runtime::Component {
 public:
  AttentionComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  runtime::Input<CandidatesMessage>& candidates_;
  runtime::Input<JointStateMessage>& joints_;
  runtime::Output<SelectionMessage>& selection_;
  std::shared_ptr<const scene::Scene> scene_;
  vision::InhibitionOfReturn::Options ior_options_;
  std::optional<vision::InhibitionOfReturn> ior_;
  double lost_after_s_ = 1.5;
  double fixation_tolerance_m_ = 0.05;
  double explore_after_s_ = 0.5;
  double home_distance_m_ = 3.0;
  double idle_since_ = 0.0;
  SelectionMessage current_;
  double last_seen_ = 0.0;
  int64_t next_id_ = 0;
};

class CamShiftComponent : public runtime::Component {
 public:
  CamShiftComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  std::string eye_;
  runtime::Input<runtime::ImageMessage>& image_;
  runtime::Input<SelectionMessage>& selection_;
  runtime::Output<TrackMessage>& track_;
  bool left_ = true;
  double reseed_fraction_ = 0.5;
  vision::CamShiftTracker::Options options_;
  std::unique_ptr<vision::CamShiftTracker> tracker_;
  int64_t target_id_ = -1;
};

class TriangulateComponent : public runtime::Component {
 public:
  TriangulateComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  std::string prefer_ = "detections";
  runtime::Input<TrackMessage>& left_;
  runtime::Input<TrackMessage>& right_;
  runtime::Input<SelectionMessage>& selection_;
  runtime::Output<TargetMessage>& target_;
  vision::StereoAssociator associator_;
  double max_reprojection_px_ = 4.0;
  bool prefer_tracks_ = false;
};

}  // namespace saccade::components
