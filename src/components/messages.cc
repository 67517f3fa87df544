#include "saccade/components/messages.h"

#include <fmt/format.h>

#include <string>

namespace saccade::components {

bool JointCommand::pursuit() const {
  return velocities.size() > 0 && (velocities.values().array() != 0.0).any();
}

void RegisterMessages() {
  runtime::MessageRegistry& registry = runtime::MessageRegistry::Global();
  registry.Register<JointStateMessage>();
  registry.Register<JointCommand>();
  registry.Register<CameraControlsMessage>();
  registry.Register<HeadStatusMessage>();
  registry.Register<FacesMessage>();
  registry.Register<CandidatesMessage>();
  registry.Register<SelectionMessage>();
  registry.Register<TrackMessage>();
  registry.Register<TargetMessage>();
  registry.Register<DepthMessage>();
  registry.Register<MapMessage>();
}

}  // namespace saccade::components
