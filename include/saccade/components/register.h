#pragma once
// Makes the components of the active-vision loop known to a registry by type name, and their
// message types to the message registry.
#include <string>

#include "saccade/runtime/component_registry.h"

namespace saccade::components {

/// Registers sim.cameras, sim.head, vision.undistort, vision.median, vision.sharpen,
/// vision.face_detector, vision.stereo_faces, vision.attention, vision.camshift,
/// vision.triangulate, control.fixation and debug.fault, each with its one-line description, and
/// the messages (RegisterMessages). Registering into a registry that has them already does nothing.
void RegisterComponents(
    runtime::ComponentRegistry& registry = runtime::ComponentRegistry::Global());

/// A copy of `registry` with the components registered whose scenes carry the head file
/// `head` in place of their robot's head (scene::LoadOptions::head): `saccade demo --head`.
/// `origin` names the option in errors ("--head"). Throws InvalidArgument when the file does
/// not exist; the head's own errors come when the scene loads.
runtime::ComponentRegistry RegistryWithHead(
    const std::string& head, const std::string& origin,
    const runtime::ComponentRegistry& registry = runtime::ComponentRegistry::Global());

}  // namespace saccade::components
