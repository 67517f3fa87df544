#pragma once
// The annotated view of an eye, drawn from what the active-vision loop said in the current
// step (loop_outputs.h): shared by `saccade demo` (its recording) and the browser
// GUI (its camera frames).

#include <opencv2/core.hpp>
#include <string>

#include "saccade/components/demo/loop_outputs.h"

namespace saccade::components::demo {

/// The annotated view of one eye, in BGR: detections (green accepted, red rejected, with the
/// reason), the CamShift window (yellow), the target (cyan), the image centre (white cross),
/// scaled by `scale` (0.5: half size). Black when the eye has no image yet.
cv::Mat Annotate(const Latest& latest, const std::string& camera, double scale);

}  // namespace saccade::components::demo
