#include "saccade/components/sharpen_component.h"

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

SharpenComponent::SharpenComponent() {
  DeclareParam("amount", &options_.amount, "weight of the detail added back (unsharp mask)")
      .Range(vision::Sharpener::Options::kAmounts);
  DeclareParam("sigma", &options_.sigma, "Gaussian blur whose difference is the detail")
      .Range(vision::Sharpener::Options::kSigmas)
      .Unit("px");
}

void SharpenComponent::Configured() { filter_ = vision::Sharpener(options_); }

}  // namespace saccade::components
