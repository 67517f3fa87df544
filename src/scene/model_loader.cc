// Model files through Assimp (OBJ + MTL, glTF 2.0, PLY, STL, Collada, ...), flattened to
// triangle meshes in the file's frame and checked against scene.h's invariants.

#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <algorithm>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <cctype>
#include <cmath>
#include <exception>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string_view>
#include <system_error>
#include <utility>

#include "internal_assets.h"
#include "internal_mesh.h"
#include "saccade/core/error.h"
#include "saccade/scene/limits.h"

namespace saccade::scene::internal {
namespace {

namespace fs = std::filesystem;

// Triangles only, in one frame (the node graph applied), with normals where the file has
// none, validated by Assimp before we validate again.
constexpr unsigned kImportFlags = aiProcess_Triangulate | aiProcess_GenSmoothNormals |
                                  aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                                  aiProcess_ValidateDataStructure | aiProcess_FindInvalidData |
                                  aiProcess_SortByPType;

// Specular exponents outside this range are meaningless (or infinite) for Blinn-Phong.
constexpr float kMinShininess = 1.0f;
constexpr float kMaxShininess = 1024.0f;

std::string Vec(const aiVector3D& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); }

float Clamp01(float value) { return std::isfinite(value) ? std::clamp(value, 0.0f, 1.0f) : 0.0f; }

// Messages with which Assimp reports that it repaired a broken file by dropping geometry
// (glTF 2 drops faces whose indices are out of range and only warns): such a file is
// rejected rather than shown in part. Other messages (a missing .mtl, normals regenerated)
// are not data loss.
constexpr const char* kDataLossMessages[] = {
    "out-of-range indices",                        // glTF 2: faces dropped
    "Invalid face index",                          // OBJ: face refers to a missing vertex
    "fails on mesh positions",                     // FindInvalidData: INF/NAN positions
    "Deleting mesh",                               // a mesh without positions
    "not compatible with the TRIANGLES mode",      // glTF: vertices dropped
    "number of faces in the header is incorrect",  // OFF: truncated
};

// Collects what Assimp logs (warnings and errors) while importing.
class LogCapture : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    if (message == nullptr || !data_loss_.empty()) return;
    std::string text(message);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    // "Warn,  T0: text" -> "text".
    if (const auto colon = text.find(": "); colon != std::string::npos && colon < 16) {
      text = text.substr(colon + 2);
    }
    for (const char* pattern : kDataLossMessages) {
      if (text.find(pattern) != std::string::npos) data_loss_ = text;
    }
    if (first_message_.empty()) first_message_ = text;
  }
  /// The first message that reports lost data; empty when none.
  const std::string& data_loss() const { return data_loss_; }
  const std::string& first_message() const { return first_message_; }

 private:
  std::string data_loss_;
  std::string first_message_;
};

// Assimp's logger is a process-wide singleton: imports are serialised while it is attached
// (models load once, when a scene loads; the cost is nil).
std::mutex& ImportMutex() {
  static std::mutex mutex;
  return mutex;
}

// Reads a file with Assimp. Returns nullptr when Assimp fails; `reason` is then why, and
// otherwise the message reporting lost data, if any.
const aiScene* Import(Assimp::Importer& importer, const std::string& name, std::string* reason,
                      bool* data_loss) {
  const std::lock_guard<std::mutex> lock(ImportMutex());
  const bool own_logger = Assimp::DefaultLogger::isNullLogger();
  if (own_logger) Assimp::DefaultLogger::create(nullptr, Assimp::Logger::NORMAL, 0);
  LogCapture capture;
  constexpr unsigned kSeverities = Assimp::Logger::Err | Assimp::Logger::Warn;
  Assimp::DefaultLogger::get()->attachStream(&capture, kSeverities);
  const aiScene* scene = nullptr;
  std::string exception;
  try {
    scene = importer.ReadFile(name, kImportFlags);
  } catch (const std::exception& error) {
    exception = error.what();
  }
  Assimp::DefaultLogger::get()->detachStream(&capture, kSeverities);
  if (own_logger) Assimp::DefaultLogger::kill();
  *data_loss = false;
  if (!exception.empty()) {
    *reason = "Assimp failed: " + exception;
    return nullptr;
  }
  if (scene == nullptr) {
    *reason = importer.GetErrorString();
    if (reason->empty()) *reason = capture.first_message();
    if (reason->empty()) *reason = "unknown error";
    if (!capture.data_loss().empty() && capture.data_loss() != *reason) {
      *reason += " (" + capture.data_loss() + ")";
    }
    return nullptr;
  }
  *data_loss = !capture.data_loss().empty();
  *reason = capture.data_loss();
  return scene;
}

// A PLY file's header against the model limits and the file's size, before Assimp allocates
// what the header claims (Assimp reserves for every declared element: a 200-byte file that
// declares 50 million faces took 3 GB and a minute and a half). Each property of an element
// takes at least one byte (binary) or two characters (ASCII: a digit and a separator), so a
// header declaring more than the file can hold is a lie. Other formats: nothing to do here.
void CheckPlyHeader(const fs::path& path, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line.substr(0, 3) != "ply") return;
  std::error_code ec;
  const auto file_bytes = static_cast<int64_t>(fs::file_size(path, ec));
  if (ec) return;  // Assimp reports what it cannot read
  const auto fail = [&](const std::string& what) { throw FileError(name, 0, "", what); };
  bool ascii = false;
  std::string element;
  int64_t count = 0, properties = 0, least_bytes = 0;
  const auto close_element = [&] { least_bytes += count * properties * (ascii ? 2 : 1); };
  for (int lines = 0; std::getline(in, line) && lines < 10000; ++lines) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") {
      std::string kind;
      words >> kind;
      ascii = kind == "ascii";
    } else if (word == "element") {
      close_element();
      words >> element >> count;
      properties = 0;
      if (!words || count < 0) fail("PLY header: malformed element line '" + line + "'");
      if (element == "vertex" && count > kMaxModelVertices) {
        fail(
            fmt::format("the PLY header declares {} vertices, more than the {} a model may have "
                        "(scene/limits.h)",
                        count, kMaxModelVertices));
      }
      if (element == "face" && count > kMaxModelTriangles) {
        fail(
            fmt::format("the PLY header declares {} faces, more than the {} triangles a model "
                        "may have (scene/limits.h)",
                        count, kMaxModelTriangles));
      }
    } else if (word == "property") {
      ++properties;
    } else if (word == "end_header") {
      close_element();
      if (least_bytes > file_bytes) {
        fail(
            fmt::format("the PLY header declares elements that need at least {} bytes, but the "
                        "file holds {} (a truncated file or a lying header)",
                        least_bytes, file_bytes));
      }
      return;
    }
  }
}

// A binary STL's header (80 bytes, then the triangle count as a little-endian uint32, then
// 50 bytes a triangle) against the model limits and the file's size, so that a 134-byte file
// claiming 50 million triangles is refused by its count, not by Assimp's guess at its format.
// Files whose extension is not .stl, and ASCII STL ("solid" and not the binary size), pass.
void CheckStlHeader(const fs::path& path, const std::string& name) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != ".stl") return;
  std::error_code ec;
  const auto file_bytes = static_cast<int64_t>(fs::file_size(path, ec));
  if (ec || file_bytes < 84) return;  // Assimp reports what it cannot read
  std::ifstream in(path, std::ios::binary);
  char header[84] = {};
  if (!in.read(header, sizeof(header))) return;
  const auto* bytes = reinterpret_cast<const unsigned char*>(header + 80);
  const int64_t count = int64_t{bytes[0]} | int64_t{bytes[1]} << 8 | int64_t{bytes[2]} << 16 |
                        int64_t{bytes[3]} << 24;
  const int64_t binary_bytes = 84 + 50 * count;
  if (std::string_view(header, 5) == "solid" && binary_bytes != file_bytes) return;  // ASCII
  const auto fail = [&](const std::string& what) { throw FileError(name, 0, "", what); };
  if (count > kMaxModelTriangles) {
    fail(
        fmt::format("the binary STL header declares {} triangles, more than the {} a model may "
                    "have (scene/limits.h)",
                    count, kMaxModelTriangles));
  }
  if (binary_bytes > file_bytes) {
    fail(
        fmt::format("the binary STL header declares {} triangles, which need {} bytes, but the "
                    "file holds {} (a truncated file or a lying header)",
                    count, binary_bytes, file_bytes));
  }
}

class ModelReader {
 public:
  ModelReader(const fs::path& path, const std::shared_ptr<const Texture>& texture_override,
              AssetCache& cache)
      : path_(path), name_(path.string()), texture_override_(texture_override), cache_(cache) {}

  Model Read() {
    Assimp::Importer importer;
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    CheckPlyHeader(path_, name_);
    CheckStlHeader(path_, name_);
    std::string reason;
    bool data_loss = false;
    const aiScene* scene = Import(importer, name_, &reason, &data_loss);
    if (scene == nullptr) {
      // Assimp's words for a file whose meshes are all points or lines, or that has none.
      for (const char* empty : {"No meshes remaining", "contains no faces", "has no faces",
                                "At least one mesh must be there"}) {
        if (reason.find(empty) != std::string::npos) {
          Fail("the model has no triangles (points and lines are not drawn); Assimp: " + reason);
        }
      }
      Fail("not a readable model: " + reason);
    }
    if (data_loss) Fail("a malformed model (Assimp dropped part of it): " + reason);
    if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mNumMeshes == 0 ||
        scene->mMeshes == nullptr) {
      Fail("the model has no triangles (points and lines are not drawn)");
    }
    int64_t triangles = 0, vertices = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      if (scene->mMeshes[m] == nullptr) continue;
      triangles += scene->mMeshes[m]->mNumFaces;
      vertices += scene->mMeshes[m]->mNumVertices;
    }
    if (triangles > kMaxModelTriangles || vertices > kMaxModelVertices) {
      Fail(
          fmt::format("{} triangles and {} vertices, more than the {} and {} a model may have "
                      "(scene/limits.h)",
                      triangles, vertices, kMaxModelTriangles, kMaxModelVertices));
    }
    scene_ = scene;
    Model model;
    model.source = name_;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* mesh = scene->mMeshes[m];
      if (mesh == nullptr || (mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
      Mesh converted = ConvertMesh(*mesh, m);
      if (converted.indices.empty()) continue;
      converted.material = MaterialIndex(mesh->mMaterialIndex, model, m);
      model.meshes.push_back(std::move(converted));
    }
    if (model.meshes.empty()) Fail("the model has no triangles (points and lines are not drawn)");
    model.bounds = ComputeBounds(model);
    std::string error;
    if (!IsValidModel(model, &error)) Fail(error);
    return model;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw FileError(name_, 0, "", what); }

  std::string MeshName(const aiMesh& mesh, unsigned index) const {
    return mesh.mName.length > 0 ? fmt::format("mesh {} '{}'", index, mesh.mName.C_Str())
                                 : fmt::format("mesh {}", index);
  }

  Mesh ConvertMesh(const aiMesh& mesh, unsigned index) const {
    Mesh out;
    const unsigned n = mesh.mNumVertices;
    if (n == 0 || mesh.mVertices == nullptr) return out;
    out.positions.reserve(n);
    for (unsigned i = 0; i < n; ++i) {
      const aiVector3D& p = mesh.mVertices[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        Fail(fmt::format("{}: vertex {} has a non-finite position {}", MeshName(mesh, index), i,
                         Vec(p)));
      }
      out.positions.emplace_back(p.x, p.y, p.z);
    }
    if (mesh.mNormals != nullptr) {
      out.normals.reserve(n);
      for (unsigned i = 0; i < n; ++i) {
        out.normals.emplace_back(mesh.mNormals[i].x, mesh.mNormals[i].y, mesh.mNormals[i].z);
      }
    }
    if (mesh.mTextureCoords[0] != nullptr) {
      out.uvs.reserve(n);
      for (unsigned i = 0; i < n; ++i) {
        const aiVector3D& uv = mesh.mTextureCoords[0][i];
        if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
          Fail(fmt::format("{}: vertex {} has a non-finite texture coordinate {}",
                           MeshName(mesh, index), i, Vec(uv)));
        }
        out.uvs.emplace_back(uv.x, uv.y);
      }
    }
    if (mesh.mFaces == nullptr) return out;
    out.indices.reserve(3 * static_cast<std::size_t>(mesh.mNumFaces));
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3 || face.mIndices == nullptr) continue;  // points and lines
      for (unsigned k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= n) {
          Fail(fmt::format("{}: face {} refers to vertex {}, but there are {} vertices",
                           MeshName(mesh, index), f, face.mIndices[k], n));
        }
        out.indices.push_back(face.mIndices[k]);
      }
    }
    // Missing, non-finite or zero normals (BoxBadNormals.glb) come back from the triangles.
    RepairNormals(out);
    return out;
  }

  int MaterialIndex(unsigned ai_index, Model& model, unsigned mesh_index) {
    if (scene_->mMaterials == nullptr || ai_index >= scene_->mNumMaterials) {
      Fail(fmt::format("mesh {} uses material {}, but there are {}", mesh_index, ai_index,
                       scene_->mNumMaterials));
    }
    if (const auto it = material_map_.find(ai_index); it != material_map_.end()) return it->second;
    model.materials.push_back(ConvertMaterial(*scene_->mMaterials[ai_index], ai_index));
    const int index = static_cast<int>(model.materials.size()) - 1;
    material_map_.emplace(ai_index, index);
    return index;
  }

  Material ConvertMaterial(const aiMaterial& material, unsigned index) {
    Material out;
    aiColor4D color(1.0f, 1.0f, 1.0f, 1.0f);
    if (material.Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS ||
        material.Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS) {
      out.base_color = {Clamp01(color.r), Clamp01(color.g), Clamp01(color.b), Clamp01(color.a)};
    }
    float opacity = 1.0f;
    if (material.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && std::isfinite(opacity)) {
      out.base_color[3] *= Clamp01(opacity);
    }
    aiColor3D specular(0.0f, 0.0f, 0.0f);
    float shininess = 0.0f;
    if (material.Get(AI_MATKEY_COLOR_SPECULAR, specular) == AI_SUCCESS &&
        material.Get(AI_MATKEY_SHININESS, shininess) == AI_SUCCESS && std::isfinite(shininess) &&
        shininess > 0.0f) {
      out.specular = Clamp01((specular.r + specular.g + specular.b) / 3.0f);
      out.shininess = std::clamp(shininess, kMinShininess, kMaxShininess);
    }
    if (texture_override_ != nullptr) {
      out.texture = texture_override_;
      out.base_color = {1.0f, 1.0f, 1.0f, 1.0f};
      return out;
    }
    aiString path;
    if (material.GetTextureCount(aiTextureType_BASE_COLOR) > 0 &&
        material.GetTexture(aiTextureType_BASE_COLOR, 0, &path) == AI_SUCCESS) {
      out.texture = ReadMaterialTexture(path.C_Str(), material, index);
    } else if (material.GetTextureCount(aiTextureType_DIFFUSE) > 0 &&
               material.GetTexture(aiTextureType_DIFFUSE, 0, &path) == AI_SUCCESS) {
      out.texture = ReadMaterialTexture(path.C_Str(), material, index);
    }
    return out;
  }

  std::string MaterialName(const aiMaterial& material, unsigned index) const {
    aiString name;
    if (material.Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0) {
      return fmt::format("material {} '{}'", index, name.C_Str());
    }
    return fmt::format("material {}", index);
  }

  std::shared_ptr<const Texture> ReadMaterialTexture(const std::string& reference,
                                                     const aiMaterial& material, unsigned index) {
    if (reference.empty()) return nullptr;
    // Embedded: "*N" or, in glTF binaries, a name the scene's texture table knows.
    if (const aiTexture* embedded = scene_->GetEmbeddedTexture(reference.c_str())) {
      return EmbeddedTexture(*embedded, reference);
    }
    if (reference[0] == '*') {
      Fail(fmt::format("{}: embedded texture '{}' does not exist", MaterialName(material, index),
                       reference));
    }
    std::string relative = reference;
    std::replace(relative.begin(), relative.end(), '\\', '/');
    // "\\..\\textures\\a.jpg" (Windows exporters) is relative to the model, not to the root.
    if (reference[0] == '\\') relative.erase(0, relative.find_first_not_of('/'));
    const fs::path folder = path_.parent_path();
    // As written (absolute, or relative to the model), then the bare file name next to the
    // model: exporters often write the absolute path of the machine the model was made on.
    const fs::path candidates[] = {folder / relative, folder / fs::path(relative).filename()};
    for (const fs::path& candidate : candidates) {
      std::error_code ec;
      if (fs::is_regular_file(candidate, ec)) {
        const fs::path canonical = fs::weakly_canonical(candidate, ec);
        try {
          return LoadTexture(ec ? candidate : canonical, cache_);
        } catch (const FileError& error) {
          Fail(fmt::format("{}: texture '{}': {}", MaterialName(material, index), reference,
                           error.what()));
        }
      }
    }
    Fail(fmt::format("{}: texture '{}' not found (looked for {})", MaterialName(material, index),
                     reference, candidates[0].lexically_normal().string()));
  }

  std::shared_ptr<const Texture> EmbeddedTexture(const aiTexture& texture,
                                                 const std::string& reference) {
    const std::string source = name_ + "#" + reference;
    if (const auto it = cache_.textures.find(source); it != cache_.textures.end()) {
      return it->second;
    }
    std::shared_ptr<const Texture> result;
    if (texture.pcData == nullptr || texture.mWidth == 0) {
      Fail(fmt::format("embedded texture '{}' has no data", reference));
    }
    if (texture.mHeight == 0) {
      // Compressed (PNG, JPEG, ...): mWidth is the size in bytes.
      try {
        result =
            DecodeTexture(reinterpret_cast<const uint8_t*>(texture.pcData), texture.mWidth, source);
      } catch (const FileError& error) {
        Fail(fmt::format("embedded texture '{}': {}", reference, error.what()));
      }
    } else {
      // Raw BGRA texels.
      constexpr unsigned kMaxSide = 1u << 15;
      if (texture.mWidth > kMaxSide || texture.mHeight > kMaxSide) {
        Fail(fmt::format("embedded texture '{}' is {} x {}, larger than {} a side", reference,
                         texture.mWidth, texture.mHeight, kMaxSide));
      }
      Image image(static_cast<int>(texture.mWidth), static_cast<int>(texture.mHeight),
                  PixelFormat::kRgba8);
      const std::size_t count = static_cast<std::size_t>(texture.mWidth) * texture.mHeight;
      for (std::size_t i = 0; i < count; ++i) {
        const aiTexel& t = texture.pcData[i];
        uint8_t* out = image.data() + 4 * i;
        out[0] = t.r;
        out[1] = t.g;
        out[2] = t.b;
        out[3] = t.a;
      }
      result = std::make_shared<const Texture>(Texture{source, std::move(image)});
    }
    cache_.textures.emplace(source, result);
    return result;
  }

  fs::path path_;
  std::string name_;
  std::shared_ptr<const Texture> texture_override_;
  AssetCache& cache_;
  const aiScene* scene_ = nullptr;
  std::map<unsigned, int> material_map_;
};

}  // namespace

std::shared_ptr<const Model> LoadModelFile(const fs::path& canonical_path,
                                           const std::shared_ptr<const Texture>& texture_override,
                                           AssetCache& cache) {
  const std::string key =
      canonical_path.string() + "\n" + (texture_override ? texture_override->source : "");
  if (const auto it = cache.models.find(key); it != cache.models.end()) return it->second;
  auto model =
      std::make_shared<const Model>(ModelReader(canonical_path, texture_override, cache).Read());
  cache.models.emplace(key, model);
  return model;
}

}  // namespace saccade::scene::internal
