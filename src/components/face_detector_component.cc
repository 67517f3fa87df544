#include "saccade/components/face_detector_component.h"

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

}  // namespace saccade::components
