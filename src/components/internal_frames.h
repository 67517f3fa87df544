#pragma once
// Small helpers of the vision components: a box's centre and the frame index of an image.
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>

#include "saccade/core/image.h"

namespace saccade::components::internal {

inline cv::Point2d Centre(const cv::Rect& box) {
  return {box.x + (box.width - 1) / 2.0, box.y + (box.height - 1) / 2.0};
}

inline int64_t FrameOf(const std::shared_ptr<const Image>& image) {
  return image ? image->metadata().frame_index : -1;
}

}  // namespace saccade::components::internal
