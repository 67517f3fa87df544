// Primitive models (scene.h): box, sphere, plane and picture, with unit normals, texture
// coordinates (uv (0, 0) at the texture's bottom-left) and counter-clockwise front faces.

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <utility>

#include "internal_mesh.h"
#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace saccade::scene {
namespace {

// Segments of a sphere: below 3 it is not a solid, above this it is only memory.
constexpr int kMaxSphereSegments = 4096;

void CheckColor(const char* function, const Eigen::Vector4f& color) {
  if (!color.allFinite() || color.minCoeff() < 0.0f || color.maxCoeff() > 1.0f) {
    throw InvalidArgument(fmt::format("{}: colour must be RGBA in [0, 1], got [{}, {}, {}, {}]",
                                      function, color[0], color[1], color[2], color[3]));
  }
}

Material PlainMaterial(const Eigen::Vector4f& color, float specular) {
  Material material;
  material.base_color = color;
  material.specular = specular;
  return material;
}

// Appends the quad centre + (+-u +-v) / 2 as two counter-clockwise triangles seen from
// n = u x v, uv (0, 0) at centre - u/2 - v/2.
void AddQuad(Mesh& mesh, const Eigen::Vector3f& centre, const Eigen::Vector3f& u,
             const Eigen::Vector3f& v) {
  const Eigen::Vector3f normal = u.cross(v).normalized();
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  const float corners[4][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f}, {-0.5f, 0.5f}};
  for (const auto& c : corners) {
    mesh.positions.push_back(centre + c[0] * u + c[1] * v);
    mesh.normals.push_back(normal);
    mesh.uvs.emplace_back(c[0] + 0.5f, c[1] + 0.5f);
  }
  for (const uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
}

std::shared_ptr<const Model> Finish(Model model) {
  model.bounds = internal::ComputeBounds(model);
  std::string error;
  SACCADE_ASSERT(internal::IsValidModel(model, &error), "primitive model: " + error);
  return std::make_shared<const Model>(std::move(model));
}

}  // namespace

std::shared_ptr<const Model> MakeBox(const Eigen::Vector4f& color) {
  CheckColor("MakeBox", color);
  Model model;
  model.source = "box";
  model.materials.push_back(PlainMaterial(color, 0.1f));
  Mesh mesh;
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX(), y = Eigen::Vector3f::UnitY(),
                        z = Eigen::Vector3f::UnitZ();
  // Each face as (u, v) with u x v its outward normal.
  const std::pair<Eigen::Vector3f, Eigen::Vector3f> faces[6] = {{y, z}, {z, y}, {z, x},
                                                                {x, z}, {x, y}, {y, x}};
  for (const auto& [u, v] : faces) AddQuad(mesh, 0.5f * u.cross(v), u, v);
  model.meshes.push_back(std::move(mesh));
  return Finish(std::move(model));
}

std::shared_ptr<const Model> MakeCylinder(const Eigen::Vector4f& color, int segments) {
  CheckColor("MakeCylinder", color);
  if (segments < 3 || segments > kMaxSphereSegments) {
    throw InvalidArgument(fmt::format("MakeCylinder: segments must be in [3, {}], got {}",
                                      kMaxSphereSegments, segments));
  }
  Model model;
  model.source = "cylinder";
  model.materials.push_back(PlainMaterial(color, 0.1f));
  Mesh mesh;
  const auto vertex = [&mesh](const Eigen::Vector3d& p, const Eigen::Vector3d& n, float u,
                              float v) {
    mesh.positions.push_back(p.cast<float>());
    mesh.normals.push_back(n.cast<float>());
    mesh.uvs.emplace_back(u, v);
    return static_cast<uint32_t>(mesh.positions.size() - 1);
  };
  // The side: a column of quads, counter-clockwise seen from outside.
  for (int j = 0; j < segments; ++j) {
    const double a0 = 2.0 * std::numbers::pi * j / segments;
    const double a1 = 2.0 * std::numbers::pi * (j + 1) / segments;
    const Eigen::Vector3d n0(std::cos(a0), std::sin(a0), 0), n1(std::cos(a1), std::sin(a1), 0);
    const float u0 = static_cast<float>(j) / segments, u1 = static_cast<float>(j + 1) / segments;
    const uint32_t a = vertex(0.5 * n0 - Eigen::Vector3d(0, 0, 0.5), n0, u0, 0.0f);
    const uint32_t b = vertex(0.5 * n1 - Eigen::Vector3d(0, 0, 0.5), n1, u1, 0.0f);
    const uint32_t c = vertex(0.5 * n1 + Eigen::Vector3d(0, 0, 0.5), n1, u1, 1.0f);
    const uint32_t d = vertex(0.5 * n0 + Eigen::Vector3d(0, 0, 0.5), n0, u0, 1.0f);
    mesh.indices.insert(mesh.indices.end(), {a, b, c, a, c, d});
  }
  // The caps: fans about their centres, facing +z and -z.
  for (const double z : {0.5, -0.5}) {
    const Eigen::Vector3d n(0, 0, z > 0 ? 1 : -1);
    const uint32_t centre = vertex(Eigen::Vector3d(0, 0, z), n, 0.5f, 0.5f);
    for (int j = 0; j < segments; ++j) {
      const double a0 = 2.0 * std::numbers::pi * j / segments;
      const double a1 = 2.0 * std::numbers::pi * (j + 1) / segments;
      const uint32_t a = vertex(Eigen::Vector3d(0.5 * std::cos(a0), 0.5 * std::sin(a0), z), n,
                                0.5f + 0.5f * static_cast<float>(std::cos(a0)),
                                0.5f + 0.5f * static_cast<float>(std::sin(a0)));
      const uint32_t b = vertex(Eigen::Vector3d(0.5 * std::cos(a1), 0.5 * std::sin(a1), z), n,
                                0.5f + 0.5f * static_cast<float>(std::cos(a1)),
                                0.5f + 0.5f * static_cast<float>(std::sin(a1)));
      if (z > 0) {
        mesh.indices.insert(mesh.indices.end(), {centre, a, b});
      } else {
        mesh.indices.insert(mesh.indices.end(), {centre, b, a});
      }
    }
  }
  model.meshes.push_back(std::move(mesh));
  return Finish(std::move(model));
}

std::shared_ptr<const Model> MakeSphere(const Eigen::Vector4f& color, int segments) {
  CheckColor("MakeSphere", color);
  if (segments < 3 || segments > kMaxSphereSegments) {
    throw InvalidArgument(fmt::format("MakeSphere: segments must be in [3, {}], got {}",
                                      kMaxSphereSegments, segments));
  }
  Model model;
  model.source = "sphere";
  model.materials.push_back(PlainMaterial(color, 0.1f));
  Mesh mesh;
  const int rings = std::max(2, segments / 2);
  // theta from the south pole (0) to the north pole (pi); phi about +z. The seam column
  // (j = segments) repeats j = 0 with u = 1.
  for (int i = 0; i <= rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2.0 * std::numbers::pi * (j == segments ? 0 : j) / segments;
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              -std::cos(theta));
      mesh.normals.push_back(n.normalized().cast<float>());
      mesh.positions.push_back((0.5 * n).cast<float>());
      mesh.uvs.emplace_back(static_cast<float>(j) / segments, static_cast<float>(i) / rings);
    }
  }
  const auto index = [segments](int i, int j) {
    return static_cast<uint32_t>(i * (segments + 1) + j);
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      // East (+phi) then north (+theta): outward, counter-clockwise seen from outside. The
      // triangles that would collapse onto a pole are left out.
      const uint32_t a = index(i, j), b = index(i, j + 1), c = index(i + 1, j + 1),
                     d = index(i + 1, j);
      if (i > 0) mesh.indices.insert(mesh.indices.end(), {a, b, c});
      if (i + 1 < rings) mesh.indices.insert(mesh.indices.end(), {a, c, d});
    }
  }
  model.meshes.push_back(std::move(mesh));
  return Finish(std::move(model));
}

std::shared_ptr<const Model> MakePlane(const Eigen::Vector4f& color) {
  CheckColor("MakePlane", color);
  Model model;
  model.source = "plane";
  model.materials.push_back(PlainMaterial(color, 0.0f));
  Mesh mesh;
  AddQuad(mesh, Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY());
  model.meshes.push_back(std::move(mesh));
  return Finish(std::move(model));
}

std::shared_ptr<const Model> MakePicture(std::shared_ptr<const Texture> texture, double height) {
  if (texture == nullptr || texture->image.empty()) {
    throw InvalidArgument("MakePicture: the texture must be a non-empty image");
  }
  if (!std::isfinite(height) || height <= 0.0) {
    throw InvalidArgument(fmt::format(
        "MakePicture: height must be a positive finite length in metres, got {}", height));
  }
  const Image& image = texture->image;
  const double width = height * image.width() / image.height();
  if (!std::isfinite(static_cast<float>(width)) || !std::isfinite(static_cast<float>(height))) {
    throw InvalidArgument(fmt::format(
        "MakePicture: a picture of {} m x {} m does not fit in single precision", width, height));
  }
  Model model;
  model.source = "picture:" + texture->source;
  Material material;
  material.texture = std::move(texture);
  model.materials.push_back(std::move(material));
  Mesh mesh;
  // In the plane x = 0 facing +x: u (the image's rightwards) is +y, v (upwards) is +z.
  AddQuad(mesh, Eigen::Vector3f::Zero(), static_cast<float>(width) * Eigen::Vector3f::UnitY(),
          static_cast<float>(height) * Eigen::Vector3f::UnitZ());
  model.meshes.push_back(std::move(mesh));
  return Finish(std::move(model));
}

}  // namespace saccade::scene
