#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace saccade::scene {
namespace {

// Primitives are built in double and stored in float: a few float ulps.
constexpr float kFloatTolerance = 1e-5f;

const Eigen::Vector4f kRed(1.0f, 0.0f, 0.0f, 1.0f);

// Checks the Mesh invariants of scene.h and that every triangle faces the way its vertex
// normals say (counter-clockwise front faces): returns the number of triangles.
int CheckMesh(const Mesh& mesh) {
  const std::size_t n = mesh.positions.size();
  EXPECT_EQ(mesh.normals.size(), n);
  EXPECT_TRUE(mesh.uvs.empty() || mesh.uvs.size() == n);
  EXPECT_EQ(mesh.indices.size() % 3, 0u);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(mesh.normals[i].norm(), 1.0f, kFloatTolerance) << "normal " << i;
  }
  for (const uint32_t index : mesh.indices) EXPECT_LT(index, n);
  int triangles = 0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const Eigen::Vector3f& a = mesh.positions[mesh.indices[t]];
    const Eigen::Vector3f& b = mesh.positions[mesh.indices[t + 1]];
    const Eigen::Vector3f& c = mesh.positions[mesh.indices[t + 2]];
    const Eigen::Vector3f face = (b - a).cross(c - a);
    EXPECT_GT(face.norm(), 0.0f) << "degenerate triangle " << t / 3;
    for (int k = 0; k < 3; ++k) {
      EXPECT_GT(face.dot(mesh.normals[mesh.indices[t + k]]), 0.0f)
          << "triangle " << t / 3 << " winds against its normals";
    }
    ++triangles;
  }
  return triangles;
}

void ExpectBounds(const Model& model, const Eigen::Vector3f& min, const Eigen::Vector3f& max) {
  EXPECT_TRUE((model.bounds.min() - min).norm() < kFloatTolerance)
      << model.bounds.min().transpose();
  EXPECT_TRUE((model.bounds.max() - max).norm() < kFloatTolerance)
      << model.bounds.max().transpose();
}

TEST(Primitives, BoxIsAUnitCubeWithOutwardFaces) {
  const auto box = MakeBox(kRed);
  ASSERT_EQ(box->meshes.size(), 1u);
  ASSERT_EQ(box->materials.size(), 1u);
  EXPECT_EQ(box->source, "box");
  EXPECT_EQ(box->materials[0].base_color, kRed);
  const Mesh& mesh = box->meshes[0];
  EXPECT_EQ(CheckMesh(mesh), 12);
  ExpectBounds(*box, Eigen::Vector3f::Constant(-0.5f), Eigen::Vector3f::Constant(0.5f));
  // Flat faces: each vertex's normal is the axis of the face it lies on, pointing outwards.
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_NEAR(mesh.positions[i].dot(mesh.normals[i]), 0.5f, kFloatTolerance);
  }
}

TEST(Primitives, SphereHasRadiusHalfAndRadialNormals) {
  const auto sphere = MakeSphere(kRed, 16);
  ASSERT_EQ(sphere->meshes.size(), 1u);
  const Mesh& mesh = sphere->meshes[0];
  // 16 segments, 8 rings: two triangles per quad except the pole caps' collapsed ones.
  EXPECT_EQ(CheckMesh(mesh), 16 * 8 * 2 - 2 * 16);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_NEAR(mesh.positions[i].norm(), 0.5f, kFloatTolerance);
    EXPECT_TRUE((mesh.normals[i] - 2.0f * mesh.positions[i]).norm() < kFloatTolerance);
    EXPECT_GE(mesh.uvs[i].minCoeff(), 0.0f);
    EXPECT_LE(mesh.uvs[i].maxCoeff(), 1.0f);
  }
  ExpectBounds(*sphere, Eigen::Vector3f::Constant(-0.5f), Eigen::Vector3f::Constant(0.5f));
}

TEST(Primitives, SphereRejectsTooFewOrTooManySegments) {
  EXPECT_THROW(MakeSphere(kRed, 2), InvalidArgument);
  EXPECT_THROW(MakeSphere(kRed, 100000), InvalidArgument);
  EXPECT_NO_THROW(MakeSphere(kRed, 3));
}

TEST(Primitives, PlaneIsTheUnitSquareFacingUp) {
  const auto plane = MakePlane(kRed);
  const Mesh& mesh = plane->meshes[0];
  EXPECT_EQ(CheckMesh(mesh), 2);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_EQ(mesh.positions[i].z(), 0.0f);
    EXPECT_EQ(mesh.normals[i], Eigen::Vector3f::UnitZ());
    // uv (0, 0) at (-0.5, -0.5), u along +x, v along +y.
    EXPECT_NEAR(mesh.uvs[i].x(), mesh.positions[i].x() + 0.5f, kFloatTolerance);
    EXPECT_NEAR(mesh.uvs[i].y(), mesh.positions[i].y() + 0.5f, kFloatTolerance);
  }
  ExpectBounds(*plane, Eigen::Vector3f(-0.5f, -0.5f, 0.0f), Eigen::Vector3f(0.5f, 0.5f, 0.0f));
}

TEST(Primitives, RejectColoursOutsideTheUnitRange) {
  EXPECT_THROW(MakeBox({1.5f, 0.0f, 0.0f, 1.0f}), InvalidArgument);
  EXPECT_THROW(MakePlane({0.0f, -0.1f, 0.0f, 1.0f}), InvalidArgument);
  EXPECT_THROW(MakeSphere({0.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f, 1.0f}),
               InvalidArgument);
}

std::shared_ptr<const Texture> MakeTexture(int width, int height) {
  return std::make_shared<const Texture>(
      Texture{"memory", Image(width, height, PixelFormat::kRgb8)});
}

// Finds the vertex with texture coordinate `uv` (exactly one must exist).
Eigen::Vector3f VertexAt(const Mesh& mesh, const Eigen::Vector2f& uv) {
  int found = -1;
  for (std::size_t i = 0; i < mesh.uvs.size(); ++i) {
    if ((mesh.uvs[i] - uv).norm() < kFloatTolerance) {
      EXPECT_EQ(found, -1) << "two vertices at uv " << uv.transpose();
      found = static_cast<int>(i);
    }
  }
  EXPECT_NE(found, -1) << "no vertex at uv " << uv.transpose();
  return found < 0 ? Eigen::Vector3f::Constant(std::nanf("")) : mesh.positions[found];
}

TEST(Primitives, PictureStandsUprightFacingPlusXWithTheImagesAspect) {
  // 200 x 100 pixels: twice as wide as high.
  const auto picture = MakePicture(MakeTexture(200, 100), 0.5);
  ASSERT_EQ(picture->meshes.size(), 1u);
  ASSERT_NE(picture->materials[0].texture, nullptr);
  EXPECT_EQ(picture->source, "picture:memory");
  const Mesh& mesh = picture->meshes[0];
  EXPECT_EQ(CheckMesh(mesh), 2);
  for (const Eigen::Vector3f& n : mesh.normals) EXPECT_EQ(n, Eigen::Vector3f::UnitX());
  // uv (0, 0) is the image's bottom-left corner; seen from +x the image's right is +y and its
  // top is +z: width 1.0 along y, height 0.5 along z, centred on the origin in x = 0.
  const float w = 0.5f, h = 0.25f;
  EXPECT_TRUE(VertexAt(mesh, {0, 0}).isApprox(Eigen::Vector3f(0, -w, -h)));
  EXPECT_TRUE(VertexAt(mesh, {1, 0}).isApprox(Eigen::Vector3f(0, w, -h)));
  EXPECT_TRUE(VertexAt(mesh, {1, 1}).isApprox(Eigen::Vector3f(0, w, h)));
  EXPECT_TRUE(VertexAt(mesh, {0, 1}).isApprox(Eigen::Vector3f(0, -w, h)));
  ExpectBounds(*picture, Eigen::Vector3f(0, -w, -h), Eigen::Vector3f(0, w, h));
}

TEST(Primitives, PictureRejectsNoTextureAndNonPositiveHeights) {
  EXPECT_THROW(MakePicture(nullptr, 1.0), InvalidArgument);
  EXPECT_THROW(MakePicture(MakeTexture(0, 0), 1.0), InvalidArgument);
  EXPECT_THROW(MakePicture(MakeTexture(4, 4), 0.0), InvalidArgument);
  EXPECT_THROW(MakePicture(MakeTexture(4, 4), -1.0), InvalidArgument);
  EXPECT_THROW(MakePicture(MakeTexture(4, 4), std::numeric_limits<double>::infinity()),
               InvalidArgument);
  EXPECT_THROW(MakePicture(MakeTexture(4, 4), 1e300), InvalidArgument);  // not a float
  EXPECT_THROW(MakePicture(MakeTexture(40000, 1), 1e36), InvalidArgument);
}

}  // namespace
}  // namespace saccade::scene
