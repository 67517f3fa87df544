#pragma once
// What the active-vision loop said in the current step, gathered from the pipeline's outputs
// by type: the newest image, faces and track of each camera, the selection, the target and
// the joints. The demo's scoring and recording and the GUI read it after each step.
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/core/image.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::components::demo {

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

/// Keeps `latest` up to date with every image, faces, track, selection, target and joints
/// message the pipeline emits. `latest` must outlive the pipeline's run.
void TapLoopOutputs(runtime::Pipeline& pipeline, Latest* latest);

}  // namespace saccade::components::demo
