#include "saccade/components/messages.h"

#include <fmt/format.h>

#include <string>

namespace saccade::components {

bool JointCommand::pursuit() const {
  return velocities.pan != 0.0 || velocities.tilt != 0.0 || velocities.left != 0.0 ||
         velocities.right != 0.0;
}

void RegisterMessages() {
  runtime::MessageRegistry& registry = runtime::MessageRegistry::Global();
  registry.Register<JointStateMessage>();
  registry.Register<JointCommand>();
  registry.Register<HeadStatusMessage>();
  registry.Register<FacesMessage>();
  registry.Register<CandidatesMessage>();
  registry.Register<SelectionMessage>();
  registry.Register<TrackMessage>();
  registry.Register<TargetMessage>();
}

}  // namespace saccade::components
