#pragma once
// Private to the scene module: the robot's drawn body, built from primitives.

#include <vector>

#include "saccade/head/head_description.h"
#include "saccade/scene/scene.h"

namespace saccade::scene::internal {

/// The body of a head, sized from its half baseline B (seed appendix A) and offsets:
/// - kBase (REP 103 axes): a pedestal under the neck;
/// - kNeck (paper axes: x left, y up, z forward; turns with pan): a column behind the eyes;
/// - kCyclopean (paper axes; turns with pan and tilt): the head plate behind the eyes;
/// - kLeftEye / kRightEye (the eye frames {l}, {r}; z along the optical axis): an eyeball
///   and a dark pupil, entirely behind the optical centre (z <= delta - margin), so that an
///   eye camera with any near plane > 0 never sees the inside of its own eye.
std::vector<RobotPart> BuildRobotBody(const head::HeadDescription& head);

}  // namespace saccade::scene::internal
