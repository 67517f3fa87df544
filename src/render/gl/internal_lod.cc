#include "render/gl/internal_lod.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace saccade::render::gl {
namespace {

// The chain stops where a level would move the surface by more than this fraction of the
// mesh's extent: no camera in a sensible scene wants coarser levels than that.
constexpr float kMaxRelativeError = 0.05f;
// ... or where a level would keep more than this fraction of the previous level's triangles
// (simplification has stalled against the error limit or the mesh's borders and seams).
constexpr double kMinReduction = 0.85;
// ... or where it would have fewer triangles than this.
constexpr std::size_t kMinLevelTriangles = 32;

float MeanEdge(const std::vector<uint32_t>& indices, const std::vector<float>& xyz) {
  double sum = 0.0;
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      const float* a = &xyz[3 * std::size_t{indices[t + k]}];
      const float* b = &xyz[3 * std::size_t{indices[t + (k + 1) % 3]}];
      const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
      sum += std::sqrt(dx * dx + dy * dy + dz * dz);
    }
  }
  return static_cast<float>(sum / static_cast<double>(std::max<std::size_t>(indices.size(), 1)));
}

}  // namespace

MeshLods BuildMeshLods(const scene::Mesh& mesh) {
  const std::size_t vertex_count = mesh.positions.size();
  const std::size_t index_count = mesh.indices.size() - mesh.indices.size() % 3;
  MeshLods lods;
  // Vertex cache order, then vertices in the order the triangles first use them (unused
  // vertices dropped). Same triangles, same winding: no geometric change.
  std::vector<uint32_t> indices(index_count);
  meshopt_optimizeVertexCache(indices.data(), mesh.indices.data(), index_count, vertex_count);
  std::vector<uint32_t> remap(vertex_count);
  const std::size_t used =
      meshopt_optimizeVertexFetchRemap(remap.data(), indices.data(), index_count, vertex_count);
  meshopt_remapIndexBuffer(indices.data(), indices.data(), index_count, remap.data());
  lods.vertex_order.assign(used, 0);
  for (std::size_t i = 0; i < vertex_count; ++i) {
    if (remap[i] != ~0u) lods.vertex_order[remap[i]] = static_cast<uint32_t>(i);
  }
  std::vector<float> xyz(3 * used);
  for (std::size_t i = 0; i < used; ++i) {
    const Eigen::Vector3f& p = mesh.positions[lods.vertex_order[i]];
    std::copy(p.data(), p.data() + 3, &xyz[3 * i]);
  }

  LodLevel full;
  full.indices = std::move(indices);
  full.mean_edge = MeanEdge(full.indices, xyz);
  lods.levels.push_back(std::move(full));
  const std::size_t triangles = index_count / 3;
  if (triangles < kMinLodTriangles || used == 0) return lods;

  // Each level is simplified from the full mesh (errors are then the distance to the real
  // surface, not accumulated), positions only: meshopt_simplify keeps vertices that share a
  // position but not their attributes (uv seams, creases) on their seams, so attributes stay
  // sane. result_error is relative to the mesh's extent; meshopt_simplifyScale turns it back
  // into model units.
  const float scale = meshopt_simplifyScale(xyz.data(), used, 3 * sizeof(float));
  const std::vector<uint32_t> source = lods.levels.front().indices;  // a copy: levels grows
  for (std::size_t target = triangles / 2; target >= kMinLevelTriangles; target /= 2) {
    std::vector<uint32_t> simplified(index_count);
    float relative_error = 0.0f;
    const std::size_t count =
        meshopt_simplify(simplified.data(), source.data(), index_count, xyz.data(), used,
                         3 * sizeof(float), 3 * target, kMaxRelativeError, 0, &relative_error);
    const std::size_t previous = lods.levels.back().indices.size();
    if (count == 0 || static_cast<double>(count) > kMinReduction * static_cast<double>(previous)) {
      break;
    }
    simplified.resize(count);
    LodLevel level;
    level.indices.resize(count);
    meshopt_optimizeVertexCache(level.indices.data(), simplified.data(), count, used);
    level.error = std::max(lods.levels.back().error, relative_error * scale);
    level.mean_edge = MeanEdge(level.indices, xyz);
    lods.levels.push_back(std::move(level));
  }
  return lods;
}

int ChooseLod(const std::vector<float>& errors, double px_per_model_unit, double max_error_px) {
  if (!(max_error_px > 0.0)) return 0;
  for (int i = static_cast<int>(errors.size()) - 1; i > 0; --i) {
    if (static_cast<double>(errors[i]) * px_per_model_unit <= max_error_px) return i;
  }
  return 0;
}

}  // namespace saccade::render::gl
