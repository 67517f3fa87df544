#include "saccade/components/image_filter_component.h"

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

ImageFilterComponent::ImageFilterComponent()
    : in_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      out_(AddOutput<runtime::ImageMessage>("image")) {}

void ImageFilterComponent::Step(const runtime::StepContext&) {
  if (!in_.fresh() || !in_.value().image) return;
  out_.Emit(runtime::ImageMessage{std::make_shared<const Image>(Apply(*in_.value().image))});
}

}  // namespace saccade::components
