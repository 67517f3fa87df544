#pragma once
// vision.camshift -- one eye's CamShift track of the selected face (vision/camshift_tracker.h),
//   seeded by its detection box, re-seeded when a detection of the same target lies farther
//   than reseed_fraction of its width from the track, re-detected when lost. A detection that
//   arrives late (vision.face_detector's latency_steps) seeds the track in the image it was
//   found in, one of the last few it kept, and the track catches up through the images since.
//   It follows the selected face only: a new target with no detection of it yet, or attention
//   exploring (its home point, not a face), ends the last face's track (target_id -1 while
//   exploring), so that neither triangulation nor the detectors go on following it.
//   inputs: image (runtime.image, required), selection (vision.selection, required)
//   outputs: track (vision.track)
// Parameters: declared in the constructor (docs/components.md lists them).
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"
#include "saccade/vision/camshift_tracker.h"

namespace saccade::components {

class CamShiftComponent : public runtime::Component {
 public:
  CamShiftComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  void Configured() override;

 private:
  // An image it saw, and where its track was in it (when tracking).
  struct Seen {
    std::shared_ptr<const Image> image;
    std::optional<cv::Point2d> centre;
  };
  // Starts the track at `box` in recent_[from] and follows it to the newest image.
  bool StartAndCatchUp(std::size_t from, const cv::Rect& box);

  std::string eye_;
  runtime::Input<runtime::ImageMessage>& image_;
  runtime::Input<SelectionMessage>& selection_;
  runtime::Output<TrackMessage>& track_;
  bool left_ = true;
  double reseed_fraction_ = 0.5;
  vision::CamShiftTracker::Options options_;
  std::unique_ptr<vision::CamShiftTracker> tracker_;
  int64_t target_id_ = -1;
  int history_frames_ = 8;
  std::deque<Seen> recent_;  // oldest first; the newest is this step's image
};

}  // namespace saccade::components
