#pragma once
// Private to the scene module: checks of the Mesh/Model invariants stated in scene.h, shared
// by the model loader, the primitives and the Scene constructor.

#include <string>

#include "saccade/scene/scene.h"

namespace saccade::scene::internal {

/// Whether `model` keeps every invariant of scene.h: at least one triangle; per mesh, three
/// indices per triangle each < positions.size(), one finite unit normal per position, uvs
/// empty or one finite pair per position, finite positions, a valid material index; every
/// material colour finite in [0, 1]. Sets `error` (what and where) when not.
bool IsValidModel(const Model& model, std::string* error);

/// The box around every position of every mesh (empty when there are none).
Eigen::AlignedBox3f ComputeBounds(const Model& model);

/// Unit normals from the triangles (area-weighted) for every vertex whose normal is missing,
/// not finite or of zero length; others are kept and re-normalised. A vertex on no
/// non-degenerate triangle gets +z. Resizes `mesh.normals` to one per position.
void RepairNormals(Mesh& mesh);

}  // namespace saccade::scene::internal
