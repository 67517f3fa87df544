#include "internal_mesh.h"

#include <fmt/format.h>

#include <cmath>

namespace saccade::scene::internal {
namespace {

// |n| may differ from 1 by this after float normalisation (a few ulps of float).
constexpr float kUnitTolerance = 1e-4f;

bool IsFinite(const Eigen::Vector3f& v) { return v.allFinite(); }

}  // namespace

bool IsValidModel(const Model& model, std::string* error) {
  const auto fail = [error](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (model.materials.empty()) return fail("has no material");
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    const Material& material = model.materials[m];
    const Eigen::Vector4f& c = material.base_color;
    if (!c.allFinite() || c.minCoeff() < 0.0f || c.maxCoeff() > 1.0f) {
      return fail(fmt::format("material {}: base colour must be finite in [0, 1]", m));
    }
    if (!std::isfinite(material.specular) || material.specular < 0.0f || material.specular > 1.0f) {
      return fail(
          fmt::format("material {}: specular must be in [0, 1], got {}", m, material.specular));
    }
    if (!std::isfinite(material.shininess) || material.shininess <= 0.0f) {
      return fail(
          fmt::format("material {}: shininess must be positive, got {}", m, material.shininess));
    }
    if (material.texture != nullptr) {
      const Image& image = material.texture->image;
      if (image.empty() ||
          (image.format() != PixelFormat::kRgb8 && image.format() != PixelFormat::kRgba8)) {
        return fail(fmt::format("material {}: texture '{}' must be a non-empty rgb8 or rgba8 image",
                                m, material.texture->source));
      }
    }
  }
  std::size_t triangles = 0;
  for (std::size_t k = 0; k < model.meshes.size(); ++k) {
    const Mesh& mesh = model.meshes[k];
    const std::size_t n = mesh.positions.size();
    if (mesh.material < 0 || static_cast<std::size_t>(mesh.material) >= model.materials.size()) {
      return fail(fmt::format("mesh {}: material index {} out of range (there are {})", k,
                              mesh.material, model.materials.size()));
    }
    if (mesh.normals.size() != n) {
      return fail(fmt::format("mesh {}: {} normals for {} positions", k, mesh.normals.size(), n));
    }
    if (!mesh.uvs.empty() && mesh.uvs.size() != n) {
      return fail(fmt::format("mesh {}: {} uvs for {} positions", k, mesh.uvs.size(), n));
    }
    if (mesh.indices.size() % 3 != 0) {
      return fail(fmt::format("mesh {}: {} indices, not a multiple of 3", k, mesh.indices.size()));
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!IsFinite(mesh.positions[i])) {
        return fail(fmt::format("mesh {}: position {} is not finite", k, i));
      }
      if (!IsFinite(mesh.normals[i]) || std::abs(mesh.normals[i].norm() - 1.0f) > kUnitTolerance) {
        return fail(fmt::format("mesh {}: normal {} is not a finite unit vector", k, i));
      }
      if (!mesh.uvs.empty() && !mesh.uvs[i].allFinite()) {
        return fail(fmt::format("mesh {}: texture coordinate {} is not finite", k, i));
      }
    }
    for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
      if (mesh.indices[i] >= n) {
        return fail(fmt::format("mesh {}: index {} = {} is out of range ({} positions)", k, i,
                                mesh.indices[i], n));
      }
    }
    triangles += mesh.indices.size() / 3;
  }
  if (triangles == 0) return fail("has no triangles");
  return true;
}

Eigen::AlignedBox3f ComputeBounds(const Model& model) {
  Eigen::AlignedBox3f bounds;  // empty
  for (const Mesh& mesh : model.meshes) {
    for (const Eigen::Vector3f& p : mesh.positions) bounds.extend(p);
  }
  return bounds;
}

void RepairNormals(Mesh& mesh) {
  const std::size_t n = mesh.positions.size();
  mesh.normals.resize(n, Eigen::Vector3f::Zero());
  std::vector<bool> bad(n, false);
  bool any_bad = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f& normal = mesh.normals[i];
    const float length = normal.norm();
    // A length this small cannot be normalised to a meaningful direction in float.
    bad[i] = !IsFinite(normal) || !std::isfinite(length) || length < 1e-12f;
    any_bad = any_bad || bad[i];
    if (!bad[i]) mesh.normals[i] = normal / length;
  }
  if (!any_bad) return;
  // Area-weighted face normals (the cross product's length is twice the area).
  std::vector<Eigen::Vector3f> sums(n, Eigen::Vector3f::Zero());
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (a >= n || b >= n || c >= n) continue;  // rejected later by IsValidModel
    const Eigen::Vector3f face =
        (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
    if (!IsFinite(face)) continue;
    sums[a] += face;
    sums[b] += face;
    sums[c] += face;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!bad[i]) continue;
    const float length = sums[i].norm();
    mesh.normals[i] = (std::isfinite(length) && length > 1e-20f) ? Eigen::Vector3f(sums[i] / length)
                                                                 : Eigen::Vector3f::UnitZ();
  }
}

}  // namespace saccade::scene::internal
