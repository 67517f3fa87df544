#include "render/gl/internal_gpu_resources.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "render/gl/internal_gl_util.h"
#include "render/gl/internal_lod.h"
#include "saccade/core/error.h"

namespace saccade::render::gl {
namespace {

// Interleaved vertex layout of GpuMesh.
struct Vertex {
  float position[3];
  float normal[3];
  float uv[2];
};
static_assert(sizeof(Vertex) == 32);

template <typename Index>
void UploadIndices(const std::vector<uint32_t>& indices) {
  if constexpr (sizeof(Index) == sizeof(uint32_t)) {
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(),
                 GL_STATIC_DRAW);
  } else {
    std::vector<Index> narrow(indices.begin(), indices.end());
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(narrow.size() * sizeof(Index)),
                 narrow.data(), GL_STATIC_DRAW);
  }
}

// Whether the mesh is closed, consistently wound and outward facing (GpuMesh::closed). Vertices are
// welded by exact position first, since seams (uv, normals) duplicate them; degenerate triangles,
// which draw nothing, are ignored.
bool IsClosed(const scene::Mesh& mesh) {
  std::map<std::array<float, 3>, uint32_t> welded;
  std::vector<uint32_t> id(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Eigen::Vector3f& p = mesh.positions[i];
    id[i] = welded
                .emplace(std::array<float, 3>{p.x(), p.y(), p.z()},
                         static_cast<uint32_t>(welded.size()))
                .first->second;
  }
  // Directed edges, each must appear once, and its reverse once.
  std::vector<uint64_t> edges;
  edges.reserve(mesh.indices.size());
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t v[3] = {id[mesh.indices[t]], id[mesh.indices[t + 1]], id[mesh.indices[t + 2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;
    for (int k = 0; k < 3; ++k) {
      edges.push_back(uint64_t{v[k]} << 32 | v[(k + 1) % 3]);
    }
  }
  if (edges.empty()) return false;
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  for (const uint64_t edge : edges) {
    const uint64_t reverse = edge << 32 | edge >> 32;
    if (!std::binary_search(edges.begin(), edges.end(), reverse)) return false;
  }
  // Wound counter-clockwise seen from outside: positive enclosed volume (divergence theorem).
  // An inside-out mesh would lose its visible side to culling; it stays two-sided.
  double volume6 = 0.0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const Eigen::Vector3d a = mesh.positions[mesh.indices[t]].cast<double>();
    const Eigen::Vector3d b = mesh.positions[mesh.indices[t + 1]].cast<double>();
    const Eigen::Vector3d c = mesh.positions[mesh.indices[t + 2]].cast<double>();
    volume6 += a.dot(b.cross(c));
  }
  return volume6 > 0.0;
}

GpuMesh UploadMesh(const scene::Mesh& mesh) {
  GpuMesh gpu;
  gpu.material = mesh.material;
  gpu.closed = IsClosed(mesh);
  gpu.flat = !mesh.normals.empty();
  for (std::size_t t = 0; gpu.flat && t + 2 < mesh.indices.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
      if (mesh.normals[a] != mesh.normals[b]) gpu.flat = false;
    }
  }
  const MeshLods lods = BuildMeshLods(mesh);
  std::vector<uint32_t> indices;  // every level, one after the other
  for (const LodLevel& level : lods.levels) {
    GpuLod lod;
    lod.index_count = static_cast<GLsizei>(level.indices.size());
    lod.offset_bytes = indices.size();  // in indices until the index type is known
    lod.error = level.error;
    lod.mean_edge = level.mean_edge;
    gpu.levels.push_back(lod);
    gpu.errors.push_back(level.error);
    indices.insert(indices.end(), level.indices.begin(), level.indices.end());
  }
  std::vector<Vertex> vertices(lods.vertex_order.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const uint32_t source = lods.vertex_order[i];
    Vertex& v = vertices[i];
    const Eigen::Vector3f& p = mesh.positions[source];
    const Eigen::Vector3f n =
        source < mesh.normals.size() ? mesh.normals[source] : Eigen::Vector3f::UnitZ();
    const Eigen::Vector2f uv =
        source < mesh.uvs.size() ? mesh.uvs[source] : Eigen::Vector2f::Zero();
    v = Vertex{{p.x(), p.y(), p.z()}, {n.x(), n.y(), n.z()}, {uv.x(), uv.y()}};
  }
  glGenVertexArrays(1, &gpu.vao);
  glBindVertexArray(gpu.vao);
  glGenBuffers(1, &gpu.vertex_buffer);
  glBindBuffer(GL_ARRAY_BUFFER, gpu.vertex_buffer);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)),
               vertices.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<const void*>(offsetof(Vertex, position)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<const void*>(offsetof(Vertex, normal)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<const void*>(offsetof(Vertex, uv)));
  glGenBuffers(1, &gpu.index_buffer);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.index_buffer);
  // 16-bit indices halve the index traffic of meshes with at most 65536 vertices.
  if (vertices.size() <= std::numeric_limits<uint16_t>::max() + std::size_t{1}) {
    gpu.index_type = GL_UNSIGNED_SHORT;
    UploadIndices<uint16_t>(indices);
  } else {
    gpu.index_type = GL_UNSIGNED_INT;
    UploadIndices<uint32_t>(indices);
  }
  const std::size_t index_size = gpu.index_type == GL_UNSIGNED_SHORT ? 2 : 4;
  for (GpuLod& lod : gpu.levels) lod.offset_bytes *= index_size;
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return gpu;
}

}  // namespace

GpuResources::GpuResources(bool anisotropic) {
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size_);
  if (anisotropic &&
      (epoxy_gl_version() >= 46 || epoxy_has_gl_extension("GL_ARB_texture_filter_anisotropic") ||
       epoxy_has_gl_extension("GL_EXT_texture_filter_anisotropic"))) {
    GLfloat max_anisotropy = 0.0f;
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY_EXT, &max_anisotropy);
    max_anisotropy_ = std::min(max_anisotropy, 8.0f);
  }
}

GpuResources::~GpuResources() {
  for (auto& [model, gpu] : models_) {
    for (GpuMesh& mesh : gpu->meshes) {
      glDeleteVertexArrays(1, &mesh.vao);
      glDeleteBuffers(1, &mesh.vertex_buffer);
      glDeleteBuffers(1, &mesh.index_buffer);
    }
  }
  for (auto& [texture, name] : textures_) glDeleteTextures(1, &name);
  if (ground_vao_ != 0) glDeleteVertexArrays(1, &ground_vao_);
  if (ground_buffer_ != 0) glDeleteBuffers(1, &ground_buffer_);
}

const GpuModel& GpuResources::Get(const scene::Model& model) {
  auto found = models_.find(&model);
  if (found != models_.end()) return *found->second;
  auto gpu = std::make_unique<GpuModel>();
  gpu->bounds = model.bounds;
  for (const scene::Material& material : model.materials) {
    GpuMaterial m;
    m.base_color = material.base_color;
    m.specular = material.specular;
    m.shininess = material.shininess;
    if (material.texture) m.texture = GetTexture(*material.texture, model.source);
    gpu->materials.push_back(m);
  }
  if (gpu->materials.empty()) gpu->materials.emplace_back();
  for (const scene::Mesh& mesh : model.meshes) {
    if (mesh.indices.empty() || mesh.positions.empty()) continue;
    gpu->meshes.push_back(UploadMesh(mesh));
    GpuMesh& last = gpu->meshes.back();
    if (last.material < 0 || last.material >= static_cast<int>(gpu->materials.size())) {
      last.material = 0;
    }
  }
  CheckGlError(fmt::format("Renderer: uploading model \"{}\"", model.source));
  return *models_.emplace(&model, std::move(gpu)).first->second;
}

GLuint GpuResources::GetTexture(const scene::Texture& texture, const std::string& model_source) {
  auto found = textures_.find(&texture);
  if (found != textures_.end()) return found->second;
  const Image& image = texture.image;
  GLenum format = 0, internal_format = 0;
  switch (image.format()) {
    case PixelFormat::kRgb8:
      format = GL_RGB;
      internal_format = GL_RGB8;
      break;
    case PixelFormat::kRgba8:
      format = GL_RGBA;
      internal_format = GL_RGBA8;
      break;
    default:
      throw Error(fmt::format(
          "Renderer: texture \"{}\" of model \"{}\" is {}, expected an rgb8 or rgba8 image",
          texture.source, model_source, ToString(image.format())));
  }
  if (image.width() < 1 || image.height() < 1 || image.width() > max_texture_size_ ||
      image.height() > max_texture_size_) {
    throw Error(fmt::format(
        "Renderer: texture \"{}\" of model \"{}\" is {} x {} pixels, expected 1 to {} (the "
        "device's GL_MAX_TEXTURE_SIZE) on each side",
        texture.source, model_source, image.width(), image.height(), max_texture_size_));
  }
  GLuint name = 0;
  glGenTextures(1, &name);
  glBindTexture(GL_TEXTURE_2D, name);
  // Rows are tightly packed (3 bytes a pixel need not be 4-aligned); any size, no padding.
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internal_format), image.width(), image.height(),
               0, format, GL_UNSIGNED_BYTE, image.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  if (max_anisotropy_ > 1.0f) {
    glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY_EXT, max_anisotropy_);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  CheckGlError(fmt::format("Renderer: uploading texture \"{}\"", texture.source));
  textures_.emplace(&texture, name);
  return name;
}

GLuint GpuResources::GroundQuad(float half_size) {
  if (ground_vao_ != 0) return ground_vao_;
  const float h = half_size;
  const float corners[4][3] = {{-h, -h, 0.0f}, {h, -h, 0.0f}, {-h, h, 0.0f}, {h, h, 0.0f}};
  glGenVertexArrays(1, &ground_vao_);
  glBindVertexArray(ground_vao_);
  glGenBuffers(1, &ground_buffer_);
  glBindBuffer(GL_ARRAY_BUFFER, ground_buffer_);
  glBufferData(GL_ARRAY_BUFFER, sizeof(corners), corners, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  CheckGlError("Renderer: uploading the ground");
  return ground_vao_;
}

}  // namespace saccade::render::gl
