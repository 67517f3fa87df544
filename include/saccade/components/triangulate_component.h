#pragma once
// vision.triangulate -- the 3D target: the selection's point (triangulated detections) when
//   this frame's detections found the target, else the two eyes' CamShift tracks triangulated
//   (they bridge the frames the detector misses: motion blur, perspective), else the
//   selection's last point. `prefer: tracks` uses the tracks even when detections exist:
//   measured on the portraits, CamShift's window slides down onto the neck's skin, 22 mm
//   off the face centre at 2.2 m against 4 mm for the detections. So that the two estimates
//   do not take turns (the head would chatter between them when detections come every few
//   steps), the tracks' point is moved by the offset between the last detection of the target
//   and the tracks' point in that detection's frame: between detections the target moves as
//   the tracks move, from where the detection put it. A late detection (vision.face_detector's
//   latency_steps, and the real-time clock) is anchored in the frame it came from the same
//   way; until the tracks have a point in the frame of a detection of the target (they
//   started after it), the detection's point stands instead of theirs.
//   inputs: left, right (vision.track, required), selection (vision.selection, required)
//   outputs: target (vision.target)
// Parameters: declared in the constructor (docs/components.md lists them).
#include <Eigen/Core>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"
#include "saccade/vision/stereo_associator.h"

namespace saccade::components {

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
  // The tracks' point in the last frames (frame index, point), oldest first.
  std::deque<std::pair<int64_t, Eigen::Vector3d>> track_points_;
  // The last detection's point less the tracks' point in its frame, for target offset_target_.
  Eigen::Vector3d offset_ = Eigen::Vector3d::Zero();
  int64_t offset_target_ = -1;
};

}  // namespace saccade::components
