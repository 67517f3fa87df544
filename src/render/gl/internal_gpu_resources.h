#pragma once
// Models and textures on the GPU, uploaded once each (DESIGN.md: a model file is loaded once
// and drawn as many times as it appears): one VAO + vertex buffer + index buffer per mesh,
// one mipmapped texture per scene::Texture however many materials use it. Meshes are reordered
// for the vertex cache and dense ones get levels of detail (internal_lod.h).

#include <epoxy/gl.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <map>
#include <memory>
#include <vector>

#include "saccade/scene/scene.h"

namespace saccade::render::gl {

/// One level of detail of a GpuMesh (internal_lod.h): a range of its index buffer.
struct GpuLod {
  GLsizei index_count = 0;
  std::size_t offset_bytes = 0;  ///< into the index buffer
  /// Geometric error in the model frame (metres): 0 for the full mesh, never decreasing.
  float error = 0.0f;
  /// Mean edge length in the model frame (metres), to tell how large triangles are on screen.
  float mean_edge = 0.0f;
};

/// One uploaded mesh: interleaved position, normal, uv (32 bytes a vertex), reordered for the
/// vertex cache, and the indices of its levels of detail one after the other.
struct GpuMesh {
  GLuint vao = 0;
  GLuint vertex_buffer = 0;
  GLuint index_buffer = 0;
  /// levels[0] is the full mesh; coarser levels follow (none for small meshes).
  std::vector<GpuLod> levels;
  /// levels[i].error, for ChooseLod.
  std::vector<float> errors;
  GLenum index_type = GL_UNSIGNED_INT;  ///< GL_UNSIGNED_SHORT when the mesh allows it
  int material = 0;
  /// Closed and consistently wound (every edge shared by exactly two triangles that run it in
  /// opposite directions, vertices welded by position): its back faces can never be seen from
  /// outside, so they are culled. Open meshes (planes, pictures, most scans) are two-sided.
  bool closed = false;
  /// Every triangle has one normal at its three vertices (a faceted mesh: boxes, planes).
  bool flat = false;
};

struct GpuMaterial {
  Eigen::Vector4f base_color{1.0f, 1.0f, 1.0f, 1.0f};
  GLuint texture = 0;  ///< 0: untextured
  float specular = 0.0f;
  float shininess = 32.0f;
};

struct GpuModel {
  std::vector<GpuMesh> meshes;
  std::vector<GpuMaterial> materials;
  Eigen::AlignedBox3f bounds;  ///< model frame; empty: do not cull
};

/// Owns every GPU copy of the scene's models and textures. Needs the context current when
/// uploading and when destroyed.
class GpuResources {
 public:
  /// `anisotropic`: filter textures anisotropically (up to 8x) where the device can.
  explicit GpuResources(bool anisotropic);
  ~GpuResources();
  GpuResources(const GpuResources&) = delete;
  GpuResources& operator=(const GpuResources&) = delete;

  /// The GPU copy of a model, uploaded on first use. Throws saccade::Error when the device
  /// refuses (a texture larger than GL_MAX_TEXTURE_SIZE, out of memory), naming the source.
  const GpuModel& Get(const scene::Model& model);
  /// A unit-free quad in z = 0 with corners (+-h, +-h), h = half_size (world coordinates), for
  /// the ground; position-only VAO drawn with 4 vertices as GL_TRIANGLE_STRIP.
  GLuint GroundQuad(float half_size);

 private:
  GLuint GetTexture(const scene::Texture& texture, const std::string& model_source);

  std::map<const scene::Model*, std::unique_ptr<GpuModel>> models_;
  std::map<const scene::Texture*, GLuint> textures_;
  GLuint ground_vao_ = 0;
  GLuint ground_buffer_ = 0;
  float max_anisotropy_ = 0.0f;  ///< 0: no anisotropic filtering
  GLint max_texture_size_ = 0;
};

}  // namespace saccade::render::gl
