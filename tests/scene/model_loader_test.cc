// Model files through the scene loader: loaded once, textures found, and every malformed
// model rejected with the scene key and the model's path (assimp-testmodels' broken files).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "saccade/core/error.h"
#include "saccade/core/image_io.h"
#include "saccade/scene/scene.h"
#include "scene/scene_test_util.h"

namespace saccade::scene {
namespace {

using testing::ExpectMessageHas;
using testing::kAssets;
using testing::kAssimpModels;
using testing::LoadError;
using testing::TempDir;

// Unit normals after float normalisation: a few float ulps.
constexpr float kUnitTolerance = 1e-5f;

std::string OneModel(const std::string& file, const std::string& extra = "") {
  return "objects:\n  - name: thing\n    kind: model\n    file: \"" + file + "\"\n" + extra;
}

// Checks the invariants of scene.h's Mesh on every mesh of the model.
void ExpectValidModel(const Model& model) {
  ASSERT_FALSE(model.meshes.empty());
  for (const Mesh& mesh : model.meshes) {
    const std::size_t n = mesh.positions.size();
    ASSERT_EQ(mesh.normals.size(), n);
    EXPECT_TRUE(mesh.uvs.empty() || mesh.uvs.size() == n);
    ASSERT_GT(mesh.indices.size(), 0u);
    EXPECT_EQ(mesh.indices.size() % 3, 0u);
    for (const uint32_t i : mesh.indices) ASSERT_LT(i, n);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_TRUE(mesh.positions[i].allFinite());
      ASSERT_TRUE(mesh.normals[i].allFinite());
      EXPECT_NEAR(mesh.normals[i].norm(), 1.0f, kUnitTolerance);
    }
    ASSERT_GE(mesh.material, 0);
    ASSERT_LT(mesh.material, static_cast<int>(model.materials.size()));
  }
  for (const Mesh& mesh : model.meshes) {
    for (const auto& p : mesh.positions) EXPECT_TRUE(model.bounds.contains(p));
  }
}

class ModelLoaderTest : public ::testing::Test {
 protected:
  Scene Load(const std::string& text) const {
    return Scene::FromYamlString(text, "test.yaml", dir_.path());
  }
  // A rejected model: the scene's file, line and key, the path given, and `parts`.
  void ExpectRejected(const std::string& file, std::initializer_list<std::string> parts) const {
    const FileError error = LoadError(OneModel(file), dir_.path());
    EXPECT_EQ(error.line(), 4) << error.what();
    EXPECT_EQ(error.key(), "objects[0].file") << error.what();
    ExpectMessageHas(error, {"test.yaml:4: objects[0].file: cannot load model", file});
    ExpectMessageHas(error, parts);
  }

  TempDir dir_;
};

TEST_F(ModelLoaderTest, MugIsLoadedOnceForEveryObjectAndUnitScale) {
  const std::string mug = kAssets + "/mug/mug.obj";
  std::string text = "objects:\n";
  for (int i = 0; i < 5; ++i) {
    text += "  - {name: mug" + std::to_string(i) + ", kind: model, file: \"" + mug +
            "\", unit_scale: " + (i % 2 == 0 ? "0.01" : "0.02") + "}\n";
  }
  const Scene scene = Load(text);
  ASSERT_EQ(scene.objects().size(), 5u);
  const auto& model = scene.objects()[0].model;
  for (const Object& object : scene.objects()) EXPECT_EQ(object.model, model);
  ASSERT_EQ(scene.models().size(), 1u);
  EXPECT_EQ(scene.models()[0], model);
  EXPECT_EQ(scene.objects()[0].scale, Eigen::Vector3d::Constant(0.01));
  EXPECT_EQ(scene.objects()[1].scale, Eigen::Vector3d::Constant(0.02));
  ExpectValidModel(*model);
  // 7.2 cm high in centimetres (y up), 24544 triangles in the file.
  EXPECT_NEAR(model->bounds.max().y(), 7.19, 0.01);
  std::size_t triangles = 0;
  for (const Mesh& mesh : model->meshes) triangles += mesh.indices.size() / 3;
  EXPECT_EQ(triangles, 24544u);
  // The mug has no .mtl file: a plain material, no texture.
  EXPECT_EQ(model->materials[0].texture, nullptr);
}

TEST_F(ModelLoaderTest, TextureOverrideReplacesEveryMaterialsTexture) {
  const Scene scene =
      Load(OneModel(kAssets + "/mug/mug.obj", "    texture: \"" + kAssets + "/mug/mug.png\"\n"));
  const Model& model = *scene.objects()[0].model;
  ASSERT_NE(model.materials[0].texture, nullptr);
  EXPECT_EQ(model.materials[0].texture->image.width(), 1024);
  EXPECT_EQ(model.materials[0].texture->image.format(), PixelFormat::kRgba8);
  EXPECT_EQ(model.materials[0].base_color, Eigen::Vector4f::Ones());
  EXPECT_FALSE(model.meshes[0].uvs.empty());
}

TEST_F(ModelLoaderTest, TexturesFromMaterialsExternalAndEmbedded) {
  // Collada with a TGA next to it.
  const Scene duck = Load(OneModel(kAssimpModels + "/Collada/duck.dae"));
  const Model& duck_model = *duck.objects()[0].model;
  ExpectValidModel(duck_model);
  ASSERT_NE(duck_model.materials[0].texture, nullptr);
  EXPECT_NE(duck_model.materials[0].texture->source.find("duckCM.tga"), std::string::npos);
  // OBJ + MTL with four JPEG textures.
  const Scene spider = Load(OneModel(kAssimpModels + "/OBJ/spider.obj"));
  ExpectValidModel(*spider.objects()[0].model);
  int textured = 0;
  for (const Material& m : spider.objects()[0].model->materials) textured += m.texture != nullptr;
  EXPECT_EQ(textured, 4);
  // glTF 2 binary with its PNG embedded ("*0"), decoded from memory.
  const Scene box =
      Load(OneModel(kAssimpModels + "/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb"));
  const Model& box_model = *box.objects()[0].model;
  ExpectValidModel(box_model);
  ASSERT_NE(box_model.materials[0].texture, nullptr);
  EXPECT_NE(box_model.materials[0].texture->source.find("BoxTextured.glb#"), std::string::npos);
  EXPECT_GT(box_model.materials[0].texture->image.width(), 0);
  EXPECT_TRUE(box_model.bounds.min().isApprox(Eigen::Vector3f::Constant(-0.5f)));
  EXPECT_TRUE(box_model.bounds.max().isApprox(Eigen::Vector3f::Constant(0.5f)));
}

TEST_F(ModelLoaderTest, OtherFormatsLoad) {
  for (const std::string file :
       {"/PLY/Wuson.ply", "/STL/Wuson.stl", "/glTF2/BoxTextured-glTF/BoxTextured.gltf",
        "/glTF/CesiumMilkTruck/CesiumMilkTruck.gltf"}) {
    SCOPED_TRACE(file);
    const Scene scene = Load(OneModel(kAssimpModels + file));
    ExpectValidModel(*scene.objects()[0].model);
  }
}

TEST_F(ModelLoaderTest, BadNormalsAreRegenerated) {
  // BoxBadNormals.glb has zero-length normals: they come back unit, from the triangles.
  const Scene scene =
      Load(OneModel(kAssimpModels + "/glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb"));
  ExpectValidModel(*scene.objects()[0].model);
}

TEST_F(ModelLoaderTest, RejectsIndicesOutOfRange) {
  // Assimp drops the bad faces and only warns: the model must not load half.
  ExpectRejected(kAssimpModels + "/glTF2/IndexOutOfRange/IndexOutOfRange.gltf",
                 {"out-of-range indices"});
  ExpectRejected(kAssimpModels + "/glTF2/IndexOutOfRange/AllIndicesOutOfRange.gltf",
                 {"out-of-range indices"});
  // An OBJ face that refers to a vertex the file does not have.
  const auto obj = dir_.Write("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n");
  ExpectRejected(obj.string(), {"out of range"});
}

TEST_F(ModelLoaderTest, RejectsNonFinitePositions) {
  ExpectRejected(kAssimpModels + "/glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
                 {"INF/NAN"});
}

TEST_F(ModelLoaderTest, RejectsAMissingBuffer) {
  ExpectRejected(kAssimpModels + "/glTF2/MissingBin/BoxTextured.gltf", {"BoxTextured0.bin"});
}

TEST_F(ModelLoaderTest, RejectsEmptyAndTruncatedFiles) {
  ExpectRejected(dir_.Write("empty.obj", "").string(), {"not a readable model"});
  ExpectRejected(dir_.Write("empty.stl", "").string(), {"not a readable model"});
  // An OBJ cut off inside its vertex list: no faces left.
  ExpectRejected(dir_.Write("truncated.obj", "# cut\nv 0 0 0\nv 1 0 0\nv 0 1").string(),
                 {"no triangles"});
  // A binary glTF cut in half.
  const std::string glb = kAssimpModels + "/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
  std::ifstream in(glb, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100u);
  ExpectRejected(dir_.Write("half.glb", bytes.substr(0, bytes.size() / 2)).string(), {});
  // Not a model at all.
  ExpectRejected(dir_.Write("notes.obj", "hello\n").string(), {});
}

TEST_F(ModelLoaderTest, RejectsAPlyHeaderThatClaimsMoreThanAModelMayHaveBeforeReadingIt) {
  // Issue 18: a 200-byte PLY declaring 50 million faces took Assimp 3 GB and 98 s to refuse.
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face {}\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  ExpectRejected(dir_.Write("huge.ply", fmt::format(fmt::runtime(header), 50'000'000)).string(),
                 {"the PLY header declares 50000000 faces, more than the 10000000 triangles"});
  // Within the limit, but more than the file can hold: a lie (or a truncated file).
  ExpectRejected(dir_.Write("lying.ply", fmt::format(fmt::runtime(header), 1'000'000)).string(),
                 {"need at least 2000018 bytes, but the file holds"});
  // The honest one loads.
  const auto honest = dir_.Write("one.ply", fmt::format(fmt::runtime(header), 1));
  EXPECT_EQ(Load(OneModel(honest.string())).objects().size(), 1u);
}

TEST_F(ModelLoaderTest, RejectsABinaryStlHeaderThatClaimsMoreThanAModelMayHave) {
  // Issue 18: a model of 50 million triangles, as a 134-byte binary STL that says so.
  const auto stl = [](uint32_t count, int facets) {
    std::string bytes(80, ' ');
    for (int i = 0; i < 4; ++i) bytes += static_cast<char>((count >> (8 * i)) & 0xff);
    std::string facet(50, '\0');  // normal, three corners (floats), attribute bytes
    const float corners[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::memcpy(facet.data(), corners, sizeof(corners));
    for (int i = 0; i < facets; ++i) bytes += facet;
    return bytes;
  };
  ExpectRejected(dir_.Write("huge.stl", stl(50'000'000, 1)).string(),
                 {"the binary STL header declares 50000000 triangles, more than the 10000000"});
  // Within the limit, but more than the file holds.
  ExpectRejected(dir_.Write("lying.stl", stl(1000, 1)).string(),
                 {"declares 1000 triangles, which need 50084 bytes, but the file holds 134"});
  // The honest one loads.
  EXPECT_EQ(Load(OneModel(dir_.Write("one.stl", stl(1, 1)).string())).objects().size(), 1u);
}

TEST_F(ModelLoaderTest, RejectsModelsWithoutTriangles) {
  ExpectRejected(kAssimpModels + "/OBJ/testpoints.obj", {"no triangles"});
  ExpectRejected(kAssimpModels + "/OBJ/testline.obj", {"no triangles"});
  ExpectRejected(kAssimpModels + "/PLY/points.ply", {"no triangles"});
}

TEST_F(ModelLoaderTest, RejectsAMissingTextureNamingIt) {
  dir_.Write("textured.obj",
             "mtllib textured.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
             "usemtl painted\nf 1/1 2/2 3/3\n");
  dir_.Write("textured.mtl", "newmtl painted\nKd 1 1 1\nmap_Kd nothere.png\n");
  const FileError error = LoadError(OneModel("textured.obj"), dir_.path());
  EXPECT_EQ(error.key(), "objects[0].file");
  ExpectMessageHas(error, {"textured.obj", "'painted'", "texture 'nothere.png' not found",
                           (dir_.path() / "nothere.png").string()});
  // A texture that is not an image.
  dir_.Write("nothere.png", "not an image");
  ExpectMessageHas(LoadError(OneModel("textured.obj"), dir_.path()),
                   {"texture 'nothere.png'", "not a readable image"});
  // Once it exists, it loads; a texture override also bypasses it.
  Image image(4, 2, PixelFormat::kGray8);
  WritePng(image.view(), dir_.path() / "nothere.png");
  const Scene scene = Load(OneModel("textured.obj"));
  const auto& texture = scene.objects()[0].model->materials[0].texture;
  ASSERT_NE(texture, nullptr);
  EXPECT_EQ(texture->image.format(), PixelFormat::kRgb8);  // gray becomes RGB
  EXPECT_EQ(texture->image.width(), 4);
}

TEST_F(ModelLoaderTest, ModelAndImageFilesShareTexturesAcrossObjects) {
  const std::string text =
      "objects:\n"
      "  - {name: a, kind: picture, image: \"" +
      kAssets +
      "/astronaut.png\", height: 1}\n"
      "  - {name: b, kind: picture, image: \"" +
      kAssets +
      "/astronaut.png\", height: 2}\n"
      "  - {name: c, kind: model, file: \"" +
      kAssets + "/mug/mug.obj\", texture: \"" + kAssets + "/astronaut.png\"}\n";
  const Scene scene = Load(text);
  const auto& texture = scene.objects()[0].model->materials[0].texture;
  EXPECT_EQ(scene.objects()[1].model->materials[0].texture, texture);
  EXPECT_EQ(scene.objects()[2].model->materials[0].texture, texture);
  // Different heights: different models, one image.
  EXPECT_NE(scene.objects()[0].model, scene.objects()[1].model);
}

}  // namespace
}  // namespace saccade::scene
