#pragma once
// vision.stereo_faces -- associates the left and right faces and triangulates them (seed 4.2).
//   inputs: left, right (vision.faces, required); outputs: candidates (vision.candidates)
// Parameters: declared in the constructor (docs/components.md lists them).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"
#include "saccade/vision/stereo_associator.h"

namespace saccade::components {

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

}  // namespace saccade::components
