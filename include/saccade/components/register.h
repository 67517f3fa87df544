#pragma once
// Makes the components of the active-vision loop known to a registry by type name, and their
// message types to the message registry.
#include "saccade/runtime/component_registry.h"

namespace saccade::components {

/// Registers sim.cameras, sim.head, vision.undistort, vision.median, vision.sharpen,
/// vision.face_detector, vision.stereo_faces, vision.attention, vision.camshift,
/// vision.triangulate, control.fixation and debug.fault, each with its one-line description, and
/// the messages (RegisterMessages). Registering into a registry that has them already does nothing.
void RegisterComponents(
    runtime::ComponentRegistry& registry = runtime::ComponentRegistry::Global());

}  // namespace saccade::components
