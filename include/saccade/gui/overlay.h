#pragma once
// What the active-vision loop said in the current step, gathered from the pipeline's outputs,
// and the annotated view of an eye drawn from it: shared by `saccade demo` (its recording) and
// the browser GUI (its camera frames).

#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/core/image.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::gui {

using components::FacesMessage;
using components::JointStateMessage;
using components::SelectionMessage;
using components::TargetMessage;
using components::TrackMessage;

/// Everything the loop's outputs said during the current step.
struct Latest {
  std::map<std::string, std::shared_ptr<const Image>> images;  // by camera
  std::map<std::string, FacesMessage> faces;
  std::map<std::string, TrackMessage> tracks;
  std::optional<SelectionMessage> selection;
  std::optional<TargetMessage> target;
  std::optional<JointStateMessage> joints;
};

/// Subscribes `slot` to every output of message type T in the pipeline.
template <typename T, typename Slot>
void Tap(runtime::Pipeline& pipeline, Slot slot) {
  for (const auto& component : pipeline.components()) {
    for (const auto& output : component->outputs()) {
      if (auto* typed = dynamic_cast<runtime::Output<T>*>(output.get())) {
        typed->signal().Connect(slot);
      }
    }
  }
}

/// The annotated view of one eye, in BGR: detections (green accepted, red rejected, with the
/// reason), the CamShift window (yellow), the target (cyan), the image centre (white cross),
/// scaled by `scale` (0.5: half size). Black when the eye has no image yet.
cv::Mat Annotate(const Latest& latest, const std::string& camera, double scale);

}  // namespace saccade::gui
