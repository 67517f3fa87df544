// Levels of detail (src/render/gl/internal_lod.h): the chains built for dense meshes, the
// choice of level, and that the default RendererOptions::lod_max_error_px leaves the bench
// scene's images all but unchanged.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "render/gl/internal_lod.h"
#include "saccade/core/image.h"
#include "saccade/core/image_io.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

namespace fs = std::filesystem;

// Image tolerances of the default LOD against full detail. A level is only chosen where its
// geometric error is below a quarter pixel, so silhouettes move by less than that and
// shading by the change of the interpolated normals over sub-pixel triangles: the mean over
// the image must stay well under one 8-bit step, and strongly differing pixels (a silhouette
// pixel flipping between object and background, a specular or texture detail shifted) must
// stay rare.
constexpr double kMaxMeanAbsDifferenceDn = 0.5;  // per channel, over the whole image
constexpr int kLargeDifferenceDn = 24;           // a pixel "differs" beyond this in any channel
constexpr double kMaxLargeDifferenceFraction = 0.005;

// Triangles as (a, b, c) rotated so that the smallest index comes first (same winding).
std::vector<std::array<uint32_t, 3>> CanonicalTriangles(const std::vector<uint32_t>& indices) {
  std::vector<std::array<uint32_t, 3>> triangles;
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    std::array<uint32_t, 3> tri{indices[t], indices[t + 1], indices[t + 2]};
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    triangles.push_back(tri);
  }
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

const scene::Model& MugModel(const scene::Scene& scene) {
  for (const scene::Object& object : scene.objects()) {
    if (object.name == "mug1") return *object.model;
  }
  ADD_FAILURE() << "bench.yaml has no object mug1";
  std::abort();
}

TEST(LodTest, DenseMeshGetsAChainOfEverCoarserLevels) {
  const scene::Scene scene = scene::Scene::Load(SACCADE_SOURCE_DIR "/scenes/bench.yaml");
  const scene::Model& mug = MugModel(scene);
  for (const scene::Mesh& mesh : mug.meshes) {
    const gl::MeshLods lods = gl::BuildMeshLods(mesh);
    ASSERT_FALSE(lods.levels.empty());
    // Level 0 is the full mesh, only reordered: the same triangles, the same winding.
    std::vector<uint32_t> full;
    for (const uint32_t i : lods.levels[0].indices) full.push_back(lods.vertex_order[i]);
    EXPECT_EQ(CanonicalTriangles(full), CanonicalTriangles(mesh.indices));
    EXPECT_EQ(lods.levels[0].error, 0.0f);
    if (mesh.indices.size() / 3 < gl::kMinLodTriangles) continue;
    ASSERT_GE(lods.levels.size(), 3u) << "the mug has " << mesh.indices.size() / 3 << " triangles";
    std::cout << "mug mesh: " << mesh.indices.size() / 3 << " triangles\n";
    for (std::size_t i = 0; i < lods.levels.size(); ++i) {
      const gl::LodLevel& level = lods.levels[i];
      std::cout << "  level " << i << ": " << level.indices.size() / 3 << " triangles, error "
                << level.error << ", mean edge " << level.mean_edge << " (model units)\n";
      for (const uint32_t index : level.indices) ASSERT_LT(index, lods.vertex_order.size());
      if (i == 0) continue;
      EXPECT_LT(level.indices.size(), lods.levels[i - 1].indices.size()) << "level " << i;
      EXPECT_GE(level.error, lods.levels[i - 1].error) << "level " << i;
      EXPECT_TRUE(std::isfinite(level.error));
    }
  }
}

TEST(LodTest, SmallMeshesGetNoLevelsOfDetail) {
  const auto sphere = scene::MakeSphere(Eigen::Vector4f(1, 1, 1, 1), 16);
  for (const scene::Mesh& mesh : sphere->meshes) {
    ASSERT_LT(mesh.indices.size() / 3, gl::kMinLodTriangles);
    const gl::MeshLods lods = gl::BuildMeshLods(mesh);
    ASSERT_EQ(lods.levels.size(), 1u);
    EXPECT_EQ(lods.levels[0].indices.size(), mesh.indices.size());
  }
}

TEST(LodTest, TheDefaultSphereGetsAChainThatStaysOnTheTrueSphere) {
  // 960 triangles (32 segments, 16 rings): about 0.2 ms a view on llvmpipe, the price of 80
  // boxes. Its seam and poles repeat positions, which meshopt_simplify keeps as seams.
  const auto sphere = scene::MakeSphere(Eigen::Vector4f(1, 1, 1, 1));
  const scene::Mesh& mesh = sphere->meshes.at(0);
  ASSERT_GE(mesh.indices.size() / 3, gl::kMinLodTriangles);
  const gl::MeshLods lods = gl::BuildMeshLods(mesh);
  ASSERT_GE(lods.levels.size(), 3u);
  // The reference is the sphere itself (radius 0.5 about the origin): each triangle's centroid
  // lies inside it by about the sagitta of its chord, and a level sinks it further by about its
  // error. meshopt_simplify's error is its estimate (from quadrics), not a bound: measured here
  // the true sink exceeds it by up to a quarter, hence the margin of a half.
  const auto Sink = [&](const gl::LodLevel& level) {
    double worst = 0.0;
    for (std::size_t t = 0; t + 2 < level.indices.size(); t += 3) {
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        centroid += mesh.positions[lods.vertex_order[level.indices[t + k]]].cast<double>() / 3.0;
      }
      worst = std::max(worst, 0.5 - centroid.norm());
    }
    return worst;
  };
  const double full_sink = Sink(lods.levels[0]);
  for (std::size_t i = 0; i < lods.levels.size(); ++i) {
    const gl::LodLevel& level = lods.levels[i];
    const double sink = Sink(level);
    std::cout << "  level " << i << ": " << level.indices.size() / 3 << " triangles, error "
              << level.error << ", centroids at most " << sink << " inside (model units)\n";
    for (const uint32_t index : level.indices) ASSERT_LT(index, lods.vertex_order.size());
    EXPECT_LE(sink, full_sink + 1.5 * level.error + 1e-6) << "level " << i;
    if (i == 0) continue;
    EXPECT_LT(level.indices.size(), lods.levels[i - 1].indices.size()) << "level " << i;
    EXPECT_GE(level.error, lods.levels[i - 1].error) << "level " << i;
  }
}

TEST(LodTest, ChosenLevelNeverGetsCoarserAsTheObjectComesCloser) {
  const std::vector<float> errors{0.0f, 1e-4f, 3e-4f, 1e-3f, 4e-3f};
  constexpr double kMaxErrorPx = 0.5;
  int previous = static_cast<int>(errors.size());
  // Pixels per metre from far (1 px/m) to very close (1e6 px/m), increasing.
  for (double px_per_m = 1.0; px_per_m < 1e6; px_per_m *= 1.1) {
    const int level = gl::ChooseLod(errors, px_per_m, kMaxErrorPx);
    ASSERT_GE(level, 0);
    ASSERT_LT(level, static_cast<int>(errors.size()));
    EXPECT_LE(level, previous) << px_per_m;
    EXPECT_LE(errors[level] * px_per_m, kMaxErrorPx) << px_per_m;
    if (level + 1 < static_cast<int>(errors.size())) {
      EXPECT_GT(errors[level + 1] * px_per_m, kMaxErrorPx) << "not the coarsest: " << px_per_m;
    }
    previous = level;
  }
  EXPECT_EQ(gl::ChooseLod(errors, 1.0, 0.0), 0) << "0: full detail always";
  EXPECT_EQ(gl::ChooseLod(errors, 1e300, kMaxErrorPx), 0) << "at the near plane";
  EXPECT_EQ(gl::ChooseLod({0.0f}, 1.0, kMaxErrorPx), 0) << "no chain";
}

TEST(LodTest, InvalidMaxErrorIsRejectedNamingTheOption) {
  RendererOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  for (const double bad : {-0.1, std::nan(""), HUGE_VAL}) {
    options.lod_max_error_px = bad;
    EXPECT_FALSE(options.IsValid(&error)) << bad;
    EXPECT_NE(error.find("lod_max_error_px"), std::string::npos) << error;
  }
}

// Renders `scene` at full detail and at the default level of detail and compares the images.
void ExpectDefaultLodLooksLikeFullDetail(const scene::Scene& scene, const std::string& name) {
  RendererOptions full_options;
  full_options.lod_max_error_px = 0.0;
  const RendererOptions lod_options;  // the default
  ASSERT_GT(lod_options.lod_max_error_px, 0.0);
  const std::vector<Frame> full =
      MakeRenderer(scene, full_options)->Render(scene.InitialState(), 0);
  const std::vector<Frame> lod = MakeRenderer(scene, lod_options)->Render(scene.InitialState(), 0);
  ASSERT_EQ(full.size(), lod.size());
  for (std::size_t c = 0; c < full.size(); ++c) {
    const Image& a = *full[c].color;
    const Image& b = *lod[c].color;
    ASSERT_EQ(a.width(), b.width());
    ASSERT_EQ(a.height(), b.height());
    ASSERT_EQ(a.format(), PixelFormat::kRgb8);
    Image diff(a.width(), a.height(), PixelFormat::kRgb8);
    double sum = 0.0;
    int64_t large = 0;
    int max_difference = 0;
    const std::size_t bytes = a.size_bytes();
    for (std::size_t i = 0; i < bytes; i += 3) {
      int pixel_max = 0;
      for (int k = 0; k < 3; ++k) {
        const int d = std::abs(int{a.data()[i + k]} - int{b.data()[i + k]});
        sum += d;
        pixel_max = std::max(pixel_max, d);
        diff.data()[i + k] = static_cast<uint8_t>(std::min(255, 8 * d));  // amplified
      }
      max_difference = std::max(max_difference, pixel_max);
      large += pixel_max > kLargeDifferenceDn;
    }
    const double pixels = static_cast<double>(a.width()) * a.height();
    const double mean = sum / (3.0 * pixels);
    const double large_fraction = static_cast<double>(large) / pixels;
    const std::string camera = name + "_" + a.metadata().camera;
    std::cout << "camera " << camera << ": mean |difference| " << mean << " DN per channel, "
              << large << " pixels (" << 100.0 * large_fraction << "%) differ by more than "
              << kLargeDifferenceDn << " DN, max " << max_difference << " DN\n";
    EXPECT_LT(mean, kMaxMeanAbsDifferenceDn) << camera;
    EXPECT_LT(large_fraction, kMaxLargeDifferenceFraction) << camera;
    if (mean >= kMaxMeanAbsDifferenceDn || large_fraction >= kMaxLargeDifferenceFraction) {
      const fs::path dir = fs::temp_directory_path() / "saccade_lod_test";
      fs::create_directories(dir);
      WritePng(a.view(), dir / (camera + "_full.png"));
      WritePng(b.view(), dir / (camera + "_lod.png"));
      WritePng(diff.view(), dir / (camera + "_diff_x8.png"));
      std::cout << "images written: " << (dir / (camera + "_{full,lod,diff_x8}.png")).string()
                << "\n";
    }
  }
}

TEST(LodTest, DefaultLevelOfDetailLooksLikeFullDetailOnTheBenchScene) {
  ExpectDefaultLodLooksLikeFullDetail(scene::Scene::Load(SACCADE_SOURCE_DIR "/scenes/bench.yaml"),
                                      "bench");
}

TEST(LodTest, DefaultLevelOfDetailLooksLikeFullDetailOnSpheresNearAndFar) {
  // Spheres from 0.6 m to 8 m, shiny (the default material) and lit from the side: a silhouette
  // or a highlight that moved would show.
  std::string yaml = R"(
background: [0.62, 0.72, 0.82]
lights:
  - {type: ambient, intensity: 0.35}
  - {type: directional, direction: [0.4, -0.6, -1.0], intensity: 0.8}
ground: {size: 16, pattern: checker, cell: 0.5}
robot:
  head: )" SACCADE_SOURCE_DIR R"(/robots/popeye.yaml
  visible: false
  cameras:
    left: {calibration: {width: 640, height: 480, fx: 520, fy: 520}}
    right: {calibration: {width: 640, height: 480, fx: 520, fy: 520}}
objects:
)";
  const double distances[] = {0.6, 1.0, 1.6, 2.5, 4.0, 8.0};
  for (int i = 0; i < 6; ++i) {
    const double x = distances[i];
    const double y = 0.22 * x * (i % 2 == 0 ? -1 : 1);  // side by side, none hiding another
    yaml += "  - {name: ball" + std::to_string(i) +
            ", kind: sphere, radius: 0.08, color: [0.8, 0.3, 0.2], pose: {position: [" +
            std::to_string(x) + ", " + std::to_string(y) + ", 1.1]}}\n";
  }
  ExpectDefaultLodLooksLikeFullDetail(
      scene::Scene::FromYamlString(yaml, "<spheres near and far>", SACCADE_SOURCE_DIR), "spheres");
}

}  // namespace
}  // namespace saccade::render
