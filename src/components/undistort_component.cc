#include "saccade/components/undistort_component.h"

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

UndistortComponent::UndistortComponent() {
  DeclareParam("bilinear", &options_.bilinear, "bilinear interpolation (else nearest pixel)");
  DeclareParam("border_value", &options_.border_value,
               "grey level of the pixels that no source pixel maps to")
      .Range(vision::Undistorter::Options::kBorderValues);
}

Image UndistortComponent::Apply(const Image& image) {
  // The maps are made once per camera; a camera whose model changes gets new ones.
  const geometry::CameraModel camera = vision::CameraModelOf(image);
  if (!undistorter_ || !(undistorter_->camera() == camera)) {
    undistorter_ = std::make_unique<vision::Undistorter>(camera, options_);
  }
  return undistorter_->Apply(image);
}

}  // namespace saccade::components
