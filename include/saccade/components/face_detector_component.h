#pragma once
// vision.face_detector -- Haar faces with the cat and eye checks (vision/face_detector.h).
//   inputs: image (runtime.image, required); outputs: faces (vision.faces), every new image.
// Parameters: declared in the constructor (docs/components.md lists them).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"
#include "saccade/vision/face_detector.h"

namespace saccade::components {

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

}  // namespace saccade::components
