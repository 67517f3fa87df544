#include "saccade/components/median_component.h"

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

MedianComponent::MedianComponent() {
  DeclareParam("kernel_size", &options_.kernel_size, "side of the square window, odd")
      .Range(vision::MedianFilter::Options::kKernelSizes)
      .Unit("px");
}

void MedianComponent::Configured() { filter_ = vision::MedianFilter(options_); }

}  // namespace saccade::components
