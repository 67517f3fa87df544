#pragma once
// Private to the scene module: the robot's drawn body, from its URDF's visuals or, for POPEYE's
// legacy head file (no URDF), built from primitives.

#include <vector>

#include "internal_assets.h"
#include "saccade/head/head_model.h"
#include "saccade/scene/scene.h"

namespace saccade::scene::internal {

/// The body of a legacy POPEYE head (HeadModel::appendix_a()), sized from its half baseline B
/// (seed appendix A) and offsets, on the links of its tree (head_model.h):
/// - kBase (REP 103 axes): a pedestal under the neck;
/// - kNeck (paper axes: x left, y up, z forward; turns with pan): a column behind the eyes;
/// - kCyclopean (paper axes; turns with pan and tilt): the head plate behind the eyes;
/// - kLeftEye / kRightEye (the eye frames {l}, {r}; z along the optical axis): an eyeball
///   and a dark pupil, entirely behind the optical centre (z <= delta - margin), so that an
///   eye camera with any near plane > 0 never sees the inside of its own eye.
/// (The parts are laid out in the paper's axes and turned into the links' REP 103 axes.)
std::vector<RobotPart> BuildRobotBody(const head::HeadModel& head);

/// The URDF's visuals as parts: boxes, cylinders and spheres as primitives in the <material>'s
/// colour (light grey without one), meshes loaded once through `cache` (Assimp: STL, DAE, OBJ,
/// ...), scaled by <mesh scale>; a <material> colour, when given, replaces the mesh's own.
/// Throws FileError naming the mesh file when it cannot be loaded.
std::vector<RobotPart> BuildUrdfVisuals(const head::HeadModel& head, AssetCache& cache);

}  // namespace saccade::scene::internal
