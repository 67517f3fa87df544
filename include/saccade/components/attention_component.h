#pragma once
// vision.attention -- chooses the face to look at: the closest one that inhibition of return
//   (seed 7.2) does not suppress; sticks to it until it has been fixated for fixation_time_s
//   (then it is suppressed for suppression_time_s) or unseen for lost_after_s. With nothing to
//   look at for explore_after_s, it sends the head home (a point home_distance_m straight
//   ahead of its base), from where it looks for faces again. A fixation (and its dwell) begins
//   when the head is at rest on the target and this step's sighting of it is within
//   onset_tolerance_deg of where the eyes point; a saccade that landed off gets its correction
//   first.
//   inputs: candidates (vision.candidates, required), joints (head.joints, delay 1)
//   outputs: selection (vision.selection)
//   methods: reset (runtime.empty -> runtime.text): forgets the target and every suppressed
//            place, so that every face is new again.
// Parameters: declared in the constructor (docs/components.md lists them).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/inhibition_of_return.h"

namespace saccade::components {

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
  double onset_tolerance_deg_ = 0.1;
  double explore_after_s_ = 0.5;
  double home_distance_m_ = 3.0;
  double idle_since_ = 0.0;
  SelectionMessage current_;
  double last_seen_ = 0.0;
  int64_t next_id_ = 0;
};

}  // namespace saccade::components
