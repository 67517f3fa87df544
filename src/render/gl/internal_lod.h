#pragma once
// Dense meshes made cheap to draw (no GL here, so that it can be tested without a context).
//
// At upload each mesh gets its triangles reordered for the post-transform vertex cache and
// its vertices for fetch locality (meshoptimizer; no geometric change). Meshes of at least
// kMinLodTriangles triangles also get a chain of levels of detail, simplified with
// meshopt_simplify to 1/2, 1/4, 1/8, ... of the triangles, each with its geometric error
// (meshopt's estimate of how far the simplified surface moved, in the model's units; on the
// default sphere the true distance exceeds it by up to a quarter). Every level indexes
// the same vertices. At draw time ChooseLod picks, per object and camera, the coarsest level
// whose error projected to the image stays within RendererOptions::lod_max_error_px.

#include <cstdint>
#include <vector>

#include "saccade/scene/scene.h"

namespace saccade::render::gl {

/// Meshes with fewer triangles than this get no levels of detail: drawing them is cheap, and
/// small meshes (markers, boxes, planes) must render exactly. The default sphere (960
/// triangles, about 0.2 ms a view on llvmpipe) gets a chain: 479, 239 and 136 triangles.
constexpr std::size_t kMinLodTriangles = 512;

/// One level of detail: triangles into MeshLods::vertex_order's vertices.
struct LodLevel {
  std::vector<uint32_t> indices;  ///< three per triangle
  /// Geometric error of this level, in model units (metres): 0 for the full mesh; never
  /// decreasing along the chain.
  float error = 0.0f;
  /// Mean edge length in model units, to tell how large its triangles are on screen.
  float mean_edge = 0.0f;
};

/// A mesh prepared for drawing: its vertices reordered (vertex_order[i] is the index, in the
/// scene::Mesh, of vertex i) and its levels of detail, levels[0] being the full mesh.
struct MeshLods {
  std::vector<uint32_t> vertex_order;
  std::vector<LodLevel> levels;
};

/// Reorders `mesh` for the vertex cache and vertex fetch and, when it has at least
/// kMinLodTriangles triangles, simplifies it to a chain of coarser levels (each at most about
/// half the triangles of the one before; the chain stops where simplification stalls or the
/// error would exceed 5% of the mesh's extent). Deterministic.
MeshLods BuildMeshLods(const scene::Mesh& mesh);

/// The coarsest level whose error, at `px_per_model_unit` pixels per model unit, is at most
/// `max_error_px` pixels: errors[i] * px_per_model_unit <= max_error_px. 0 when
/// max_error_px <= 0. `errors` is the chain's LodLevel::error, non-decreasing, errors[0] = 0.
/// Never increases as px_per_model_unit grows (closer objects never get coarser levels).
int ChooseLod(const std::vector<float>& errors, double px_per_model_unit, double max_error_px);

}  // namespace saccade::render::gl
