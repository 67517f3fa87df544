#pragma once
// Private to the scene module: loading textures and model files once each (DESIGN.md: a
// model file is loaded once and drawn as many times as it appears).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "saccade/scene/scene.h"

namespace saccade::scene::internal {

/// What one scene load has read so far, by canonical path (and options), so that every file
/// is read once and shared.
struct AssetCache {
  std::map<std::string, std::shared_ptr<const Texture>> textures;
  std::map<std::string, std::shared_ptr<const Model>> models;
};

/// An image as a texture (kRgb8 or kRgba8; gray becomes RGB, 16-bit keeps its high byte).
Image ToTextureImage(Image image);

/// Reads an image file as a texture, once per canonical path. Throws FileError naming the
/// file when it cannot be read or is not an image.
std::shared_ptr<const Texture> LoadTexture(const std::filesystem::path& canonical_path,
                                           AssetCache& cache);

/// Decodes an image held in memory (PNG, JPEG, ... as stb_image reads). `source` names it.
/// Throws FileError(source) when the bytes are not an image.
std::shared_ptr<const Texture> DecodeTexture(const uint8_t* data, std::size_t size,
                                             const std::string& source);

/// Loads a model file with Assimp, once per (canonical path, texture override), and checks
/// every invariant of scene.h (finite positions, indices in range, at least one triangle);
/// non-finite or zero normals are regenerated from the triangles. Points and lines are
/// dropped. Diffuse/base-colour textures are read relative to the model's folder, or decoded
/// when embedded. `texture_override`, when not null, replaces every material's texture and
/// makes its base colour white. Throws FileError naming the model file and what is wrong.
std::shared_ptr<const Model> LoadModelFile(const std::filesystem::path& canonical_path,
                                           const std::shared_ptr<const Texture>& texture_override,
                                           AssetCache& cache);

}  // namespace saccade::scene::internal
