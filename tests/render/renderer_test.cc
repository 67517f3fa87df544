// The renderer's behaviours other than sub-pixel accuracy (marker_accuracy_test.cc): image
// size and orientation, pipelining and metadata, determinism, option errors, textures, the
// ground pattern, lighting, culling and the robot.

#include "saccade/render/renderer.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "image_camera_helpers.h"
#include "saccade/core/error.h"
#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/head_description.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::Vector3f;
using Eigen::Vector4f;

// 8-bit colours: a value rendered from a colour c in [0, 1] is round(255 c); the shading
// arithmetic in float moves it by less than one step, rounding can then add one.
constexpr int kColorToleranceLsb = 1;

// A camera looking along `forward` from `eye`, image x along `right` (both unit, orthogonal).
geometry::Pose LookPose(const Vector3d& eye, const Vector3d& forward, const Vector3d& right) {
  Eigen::Matrix3d R;
  R.col(0) = right;
  R.col(2) = forward;
  R.col(1) = forward.cross(right);
  return geometry::MakePose(R, eye);
}

scene::CameraSpec WorldCamera(const std::string& name, const geometry::Intrinsics& K,
                              const geometry::Pose& X_WC,
                              const geometry::Distortion& distortion = geometry::Distortion()) {
  return scene::CameraSpec{name, geometry::CameraModel(K, distortion), scene::CameraMount::kWorld,
                           X_WC, geometry::ClipPlanes{0.05, 50.0},     scene::SensorSpec{}};
}

scene::Light Ambient(float intensity) {
  scene::Light light;
  light.type = scene::Light::Type::kAmbient;
  light.intensity = intensity;
  return light;
}

scene::Ground NoGround() {
  scene::Ground ground;
  ground.enabled = false;
  return ground;
}

scene::Object MakeObject(const std::string& name, uint32_t id,
                         std::shared_ptr<const scene::Model> model, const geometry::Pose& X_WO,
                         const Vector3d& scale = Vector3d::Ones()) {
  scene::Object object;
  object.name = name;
  object.id = id;
  object.model = std::move(model);
  object.scale = scale;
  object.motion = scene::Motion::Static(X_WO);
  return object;
}

geometry::Pose At(const Vector3d& p) { return geometry::MakePose(Eigen::Matrix3d::Identity(), p); }

struct Rgb {
  int r, g, b;
};

Rgb PixelAt(const Image& image, int u, int v) {
  const uint8_t* p = image.row(v) + 3 * u;
  return {p[0], p[1], p[2]};
}

// The pixel nearest OpenCV's projection of p_W.
Rgb PixelOf(const Image& image, const scene::CameraSpec& camera, const Vector3d& p_W) {
  const std::optional<Vector2d> uv = camera.model.Project(camera.X_WC.inverse() * p_W);
  EXPECT_TRUE(uv.has_value());
  return PixelAt(image, static_cast<int>(std::lround(uv->x())),
                 static_cast<int>(std::lround(uv->y())));
}

void ExpectColor(const Rgb& got, const Vector3f& expected, const std::string& what) {
  EXPECT_NEAR(got.r, 255.0 * expected.x(), 0.5 + kColorToleranceLsb) << what << " (red)";
  EXPECT_NEAR(got.g, 255.0 * expected.y(), 0.5 + kColorToleranceLsb) << what << " (green)";
  EXPECT_NEAR(got.b, 255.0 * expected.z(), 0.5 + kColorToleranceLsb) << what << " (blue)";
}

// The centroid of the pixels equal to `color`, or (-1, -1).
Vector2d CentroidOf(const Image& image, const Rgb& color) {
  double su = 0, sv = 0, n = 0;
  for (int v = 0; v < image.height(); ++v) {
    for (int u = 0; u < image.width(); ++u) {
      const Rgb p = PixelAt(image, u, v);
      if (p.r == color.r && p.g == color.g && p.b == color.b) {
        su += u;
        sv += v;
        n += 1;
      }
    }
  }
  return n > 0 ? Vector2d(su / n, sv / n) : Vector2d(-1, -1);
}

const geometry::Intrinsics kVga(640, 480, 500.0, 500.0, 319.5, 239.5);

TEST(RendererTest, OddSizedCameraGivesAnImageOfExactlyThatSize) {
  const geometry::Intrinsics K(641, 479, 600.0, 590.0, 320.2, 238.9, 0.7);
  const scene::Scene world(Vector3f(0.1f, 0.2f, 0.3f), {Ambient(1.0f)}, NoGround(), {},
                           {WorldCamera("odd", K, geometry::Pose::Identity())}, std::nullopt);
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world);
  const std::vector<Frame> frames = renderer->Render(world.InitialState(), 0);
  ASSERT_EQ(frames.size(), 1u);
  const Image& image = *frames[0].color;
  EXPECT_EQ(image.width(), 641);
  EXPECT_EQ(image.height(), 479);
  EXPECT_EQ(image.format(), PixelFormat::kRgb8);
  EXPECT_EQ(image.stride(), 641u * 3u);
  // The background fills it all, last pixel included.
  ExpectColor(PixelAt(image, 640, 478), Vector3f(0.1f, 0.2f, 0.3f), "last pixel");
  ExpectColor(PixelAt(image, 0, 0), Vector3f(0.1f, 0.2f, 0.3f), "first pixel");
}

TEST(RendererTest, RowZeroIsTheTopAndColumnZeroTheLeft) {
  // Camera at the origin looking along world +z (optical frame = world frame): a red square
  // above the optical axis (y < 0 is up in the optical frame) and a green one to its right,
  // both parallel to the image plane (so their images are squares centred on the projections
  // of their centres).
  const scene::Scene world(Vector3f::Zero(), {Ambient(1.0f)}, NoGround(),
                           {MakeObject("up", 1, scene::MakePlane(Vector4f(1, 0, 0, 1)),
                                       At(Vector3d(0.0, -0.6, 3.0)), Vector3d::Constant(0.2)),
                            MakeObject("right", 2, scene::MakePlane(Vector4f(0, 1, 0, 1)),
                                       At(Vector3d(0.8, 0.0, 3.0)), Vector3d::Constant(0.2))},
                           {WorldCamera("cam", kVga, geometry::Pose::Identity())}, std::nullopt);
  const std::vector<Frame> frames = MakeRenderer(world)->Render(world.InitialState(), 0);
  const Image& image = *frames[0].color;
  const Vector2d red = CentroidOf(image, {255, 0, 0});
  const Vector2d green = CentroidOf(image, {0, 255, 0});
  // Where OpenCV puts the squares' centres: (319.5, 139.5) and (452.8, 239.5), to within the
  // aliasing of their hard edges.
  EXPECT_NEAR(red.x(), 319.5, 0.5);
  EXPECT_NEAR(red.y(), 139.5, 0.5);
  EXPECT_LT(red.y(), image.height() / 2.0) << "a point above the optical axis is in the top half";
  EXPECT_NEAR(green.x(), 319.5 + 500.0 * 0.8 / 3.0, 0.5);
  EXPECT_GT(green.x(), image.width() / 2.0) << "a point right of the axis is in the right half";
  EXPECT_NEAR(green.y(), 239.5, 0.5);
}

// A picture whose quadrants have distinct colours; the camera faces it.
TEST(RendererTest, PictureIsUprightAndNotMirrored) {
  auto texture = std::make_shared<scene::Texture>();
  texture->source = "quadrants";
  texture->image = Image(64, 48, PixelFormat::kRgb8);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      uint8_t* p = texture->image.row(y) + 3 * x;
      const bool top = y < 24, left = x < 32;
      // Top-left red, top-right green, bottom-left blue, bottom-right white.
      p[0] = (top && left) || (!top && !left) ? 255 : 0;
      p[1] = (top && !left) || (!top && !left) ? 255 : 0;
      p[2] = (!top && left) || (!top && !left) ? 255 : 0;
    }
  }
  // The picture faces +x in its plane x = 0 (scene::MakePicture), 1 m high, 1.33 m wide; the
  // camera stands at x = 2 looking back along -x, its image x along +y (the picture's right).
  const scene::CameraSpec camera = WorldCamera(
      "front", kVga, LookPose(Vector3d(2.0, 0.0, 0.0), -Vector3d::UnitX(), Vector3d::UnitY()));
  const scene::Scene world(
      Vector3f::Zero(), {Ambient(1.0f)}, NoGround(),
      {MakeObject("picture", 1, scene::MakePicture(texture, 1.0), geometry::Pose::Identity())},
      {camera}, std::nullopt);
  const std::vector<Frame> frames = MakeRenderer(world)->Render(world.InitialState(), 0);
  const Image& image = *frames[0].color;
  const double w = 4.0 / 3.0;
  ExpectColor(PixelOf(image, camera, Vector3d(0, -w / 4, 0.25)), Vector3f(1, 0, 0), "top-left");
  ExpectColor(PixelOf(image, camera, Vector3d(0, w / 4, 0.25)), Vector3f(0, 1, 0), "top-right");
  ExpectColor(PixelOf(image, camera, Vector3d(0, -w / 4, -0.25)), Vector3f(0, 0, 1), "bottom-left");
  ExpectColor(PixelOf(image, camera, Vector3d(0, w / 4, -0.25)), Vector3f(1, 1, 1), "bottom-right");
  // And in image terms: red is up and left of white.
  const Vector2d red = CentroidOf(image, {255, 0, 0});
  const Vector2d white = CentroidOf(image, {255, 255, 255});
  EXPECT_LT(red.x(), white.x());
  EXPECT_LT(red.y(), white.y());
}

TEST(RendererTest, CheckerGroundMatchesTheWorldSquares) {
  scene::Ground ground;
  ground.size = 6.0;
  ground.pattern = scene::Ground::Pattern::kChecker;
  ground.cell = 0.5;
  ground.color = Vector3f(0.8f, 0.7f, 0.6f);
  ground.color2 = Vector3f(0.2f, 0.3f, 0.1f);
  // Looking straight down from 4 m, image x along world +x.
  const scene::CameraSpec camera = WorldCamera(
      "down", kVga, LookPose(Vector3d(0.3, -0.2, 4.0), -Vector3d::UnitZ(), Vector3d::UnitX()));
  const scene::Scene world(Vector3f::Zero(), {Ambient(1.0f)}, ground, {}, {camera}, std::nullopt);
  const std::vector<Frame> frames = MakeRenderer(world)->Render(world.InitialState(), 0);
  const Image& image = *frames[0].color;
  for (int i = -4; i < 4; ++i) {
    for (int j = -3; j < 3; ++j) {
      // Square [i, i+1) x [j, j+1) cells has the first colour when i + j is even.
      const Vector3d centre((i + 0.5) * ground.cell, (j + 0.5) * ground.cell, 0.0);
      const bool first = (i + j) % 2 == 0;
      ExpectColor(PixelOf(image, camera, centre), first ? ground.color : ground.color2,
                  "square " + std::to_string(i) + ", " + std::to_string(j));
    }
  }
}

// A 10 x 10 m plane facing +z seen from above, lit by ambient plus one light.
Image LitPlane(const scene::Light& light, const scene::CameraSpec& camera, const Vector4f& color) {
  const scene::Scene world(Vector3f::Zero(), {Ambient(0.1f), light}, NoGround(),
                           {MakeObject("plane", 1, scene::MakePlane(color),
                                       geometry::Pose::Identity(), Vector3d(10, 10, 1))},
                           {camera}, std::nullopt);
  return *MakeRenderer(world)->Render(world.InitialState(), 0)[0].color;
}

TEST(RendererTest, DirectionalLightFollowsLambert) {
  const scene::CameraSpec camera = WorldCamera(
      "down", kVga, LookPose(Vector3d(0, 0, 3.0), -Vector3d::UnitZ(), Vector3d::UnitX()));
  const double angle = 40.0 * std::numbers::pi / 180.0;
  scene::Light sun;
  sun.type = scene::Light::Type::kDirectional;
  sun.intensity = 0.8f;
  sun.direction_W = Vector3d(std::sin(angle), 0.0, -std::cos(angle));
  const Vector4f color(0.5f, 0.6f, 0.7f, 1.0f);
  const Image image = LitPlane(sun, camera, color);
  const float irradiance = 0.1f + 0.8f * static_cast<float>(std::cos(angle));
  for (const Vector3d& p : {Vector3d(0, 0, 0), Vector3d(1.0, 0.7, 0), Vector3d(-1.2, -0.9, 0)}) {
    ExpectColor(PixelOf(image, camera, p), color.head<3>() * irradiance, "directional");
  }
}

TEST(RendererTest, PointLightFollowsLambertAndAttenuation) {
  const scene::CameraSpec camera = WorldCamera(
      "down", kVga, LookPose(Vector3d(0, 0, 3.0), -Vector3d::UnitZ(), Vector3d::UnitX()));
  scene::Light bulb;
  bulb.type = scene::Light::Type::kPoint;
  bulb.intensity = 0.9f;
  bulb.position_W = Vector3d(0.2, 0.1, 2.0);
  bulb.attenuation = 0.25;
  const Vector4f color(0.9f, 0.8f, 0.4f, 1.0f);
  const Image image = LitPlane(bulb, camera, color);
  for (const Vector3d& p : {Vector3d(0.2, 0.1, 0), Vector3d(1.2, 0.1, 0), Vector3d(-0.8, -1, 0)}) {
    const Vector3d to_light = bulb.position_W - p;
    const double d2 = to_light.squaredNorm();
    const double cosine = to_light.normalized().z();
    const float irradiance = 0.1f + static_cast<float>(0.9 * cosine / (1.0 + 0.25 * d2));
    ExpectColor(PixelOf(image, camera, p), color.head<3>() * irradiance, "point light");
  }
}

TEST(RendererTest, OpenMeshesAreSeenFromBothSides) {
  // A plane facing +z seen from below, and a closed box seen from outside.
  const scene::CameraSpec camera =
      WorldCamera("up", kVga, LookPose(Vector3d(0, 0, -3.0), Vector3d::UnitZ(), Vector3d::UnitX()));
  const scene::Scene world(
      Vector3f::Zero(), {Ambient(1.0f)}, NoGround(),
      {MakeObject("plane", 1, scene::MakePlane(Vector4f(0, 0, 1, 1)), At(Vector3d(-1, 0, 0))),
       MakeObject("box", 2, scene::MakeBox(Vector4f(1, 0, 0, 1)), At(Vector3d(1, 0, 0)))},
      {camera}, std::nullopt);
  const Image image = *MakeRenderer(world)->Render(world.InitialState(), 0)[0].color;
  ExpectColor(PixelOf(image, camera, Vector3d(-1, 0, 0)), Vector3f(0, 0, 1), "plane from behind");
  ExpectColor(PixelOf(image, camera, Vector3d(1, 0, -0.5)), Vector3f(1, 0, 0), "box");
}

TEST(RendererTest, ObjectsPartlyInViewAreDrawn) {
  // A large box straddling the left image border: its visible part must be there (the frustum
  // test culls only objects wholly outside).
  const scene::CameraSpec camera = WorldCamera("cam", kVga, geometry::Pose::Identity());
  const scene::Scene world(
      Vector3f::Zero(), {Ambient(1.0f)}, NoGround(),
      {MakeObject("edge", 1, scene::MakeBox(Vector4f(0, 1, 0, 1)), At(Vector3d(-2.2, 0, 3.0)),
                  Vector3d(2, 1, 0.1)),
       MakeObject("behind", 2, scene::MakeBox(Vector4f(1, 0, 0, 1)), At(Vector3d(0, 0, -3.0)))},
      {camera}, std::nullopt);
  const Image image = *MakeRenderer(world)->Render(world.InitialState(), 0)[0].color;
  ExpectColor(PixelAt(image, 0, 240), Vector3f(0, 1, 0), "left border");
  ExpectColor(PixelAt(image, 320, 240), Vector3f(0, 0, 0), "centre");
}

// A scene with the head (robots/popeye.yaml), its two eye cameras, a world camera with lens
// distortion, a checker ground, textures, a shiny sphere and every kind of light.
scene::Scene RichScene() {
  const head::HeadModel head = head::HeadModel::FromFile(SACCADE_SOURCE_DIR "/robots/popeye.yaml");
  scene::Robot robot{head, head::JointState::Popeye(0, 0, 0, 0), true, {}, 100};
  robot.parts.push_back(scene::RobotPart{head.tree().root(), At(Vector3d(0, 0, -0.3)),
                                         scene::MakeBox(Vector4f(0.2f, 0.2f, 0.2f, 1)),
                                         Vector3d(0.1, 0.1, 0.3)});
  auto texture = std::make_shared<scene::Texture>();
  texture->source = "gradient";
  texture->image = Image(37, 23, PixelFormat::kRgb8);
  for (int y = 0; y < 23; ++y) {
    for (int x = 0; x < 37; ++x) {
      uint8_t* p = texture->image.row(y) + 3 * x;
      p[0] = static_cast<uint8_t>(7 * x);
      p[1] = static_cast<uint8_t>(11 * y);
      p[2] = static_cast<uint8_t>(255 - 3 * (x + y));
    }
  }
  scene::Light sun, bulb;
  sun.type = scene::Light::Type::kDirectional;
  sun.direction_W = Vector3d(0.4, 0.3, -1.0);
  sun.intensity = 0.6f;
  bulb.type = scene::Light::Type::kPoint;
  bulb.position_W = Vector3d(1.5, 0.3, 2.0);
  bulb.attenuation = 0.2;
  scene::Ground ground;
  ground.pattern = scene::Ground::Pattern::kChecker;
  const scene::Object sphere =
      MakeObject("sphere", 2, scene::MakeSphere(Vector4f(0.9f, 0.1f, 0.1f, 1)),
                 At(Vector3d(2.0, 0.2, 1.1)), Vector3d::Constant(0.3));
  const std::vector<double> radtan = {-0.1, 0.01, 0.001, -0.002, 0.0};
  std::vector<scene::CameraSpec> cameras = {
      {"left", head.camera(0).model, scene::CameraMount::kLeftEye, geometry::Pose::Identity(),
       geometry::ClipPlanes{0.05, 50.0}, scene::SensorSpec{}},
      {"right", head.camera(1).model, scene::CameraMount::kRightEye, geometry::Pose::Identity(),
       geometry::ClipPlanes{0.05, 50.0}, scene::SensorSpec{}},
      WorldCamera(
          "rig", geometry::Intrinsics(320, 240, 260.0, 255.0, 161.0, 118.0),
          LookPose(Vector3d(-1.0, -1.5, 1.6), Vector3d(0.8, 0.6, 0.0), Vector3d(0.6, -0.8, 0.0)),
          geometry::Distortion::RadialTangential(radtan))};
  return scene::Scene(
      Vector3f(0.6f, 0.7f, 0.8f), {Ambient(0.3f), sun, bulb}, ground,
      {MakeObject("picture", 1, scene::MakePicture(texture, 0.6),
                  geometry::MakePose(geometry::RotationFromRpy(0, 0, std::numbers::pi),
                                     Vector3d(2.5, -0.3, 1.2))),
       sphere},
      cameras, robot);
}

TEST(RendererTest, SubmitAndRetrieveReturnFramesInOrderWithTheirMetadata) {
  const scene::Scene world = RichScene();
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world);
  ASSERT_EQ(renderer->camera_names(), (std::vector<std::string>{"left", "right", "rig"}));
  std::vector<scene::SceneState> states(3);
  for (int i = 0; i < 3; ++i) {
    states[i].time = 0.5 * i;
    states[i].joints = head::JointState::Popeye(0.1 * i, -0.05 * i, -0.02 * i, 0.03 * i);
  }
  EXPECT_EQ(renderer->InFlight(), 0);
  renderer->Submit(states[0], 10);
  renderer->Submit(states[1], 11);
  EXPECT_EQ(renderer->InFlight(), 2);
  EXPECT_THROW(renderer->Submit(states[2], 12), Error);
  std::vector<std::vector<Frame>> got;
  got.push_back(renderer->Retrieve());
  renderer->Submit(states[2], 12);
  got.push_back(renderer->Retrieve());
  got.push_back(renderer->Retrieve());
  EXPECT_EQ(renderer->InFlight(), 0);
  EXPECT_THROW(renderer->Retrieve(), Error);
  EXPECT_EQ(renderer->stats().frames, 3);
  EXPECT_GT(renderer->stats().total_ms, 0.0);

  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(got[i].size(), 3u);
    for (int c = 0; c < 3; ++c) {
      const scene::CameraSpec& camera = world.cameras()[c];
      const ImageMetadata& meta = got[i][c].color->metadata();
      SCOPED_TRACE("state " + std::to_string(i) + ", camera " + camera.name);
      EXPECT_EQ(meta.camera, camera.name);
      EXPECT_EQ(meta.frame_index, 10 + i);
      EXPECT_EQ(meta.time, states[i].time);
      const Eigen::Matrix4d X_WC = world.CameraPose(camera, states[i]).matrix();
      const geometry::Pose* carried = geometry::FindCameraPose(meta);
      ASSERT_NE(carried, nullptr);
      for (int k = 0; k < 16; ++k)
        EXPECT_EQ(carried->matrix()(k / 4, k % 4), X_WC(k / 4, k % 4)) << k;
      const Eigen::Matrix3d K = camera.model.intrinsics().Matrix();
      for (int k = 0; k < 9; ++k) EXPECT_EQ(testing_helpers::KAt(meta, k), K(k / 3, k % 3)) << k;
      // The metadata describes the lens as rendered: camera 2's radtan distortion, the
      // eyes' pinholes.
      EXPECT_EQ(testing_helpers::DistortionName(meta),
                geometry::ToString(camera.model.distortion().IsIdentity()
                                       ? geometry::DistortionModel::kNone
                                       : camera.model.distortion().model()));
      if (!camera.model.distortion().IsIdentity()) {
        EXPECT_EQ(testing_helpers::Coefficients(meta), camera.model.distortion().coefficients());
      } else {
        EXPECT_TRUE(testing_helpers::Coefficients(meta).empty());
      }
      const bool eye = camera.mount != scene::CameraMount::kWorld;
      EXPECT_EQ(meta.has_joints, eye);
      if (eye) {
        EXPECT_EQ(meta.joints, (std::vector<double>{states[i].joints[0], states[i].joints[1],
                                                    states[i].joints[2], states[i].joints[3]}));
        ASSERT_TRUE(meta.joint_names);
        EXPECT_EQ(*meta.joint_names, *head::JointState::PopeyeNames());
      }
      EXPECT_EQ(got[i][c].color->width(), camera.model.intrinsics().width());
      EXPECT_EQ(got[i][c].color->height(), camera.model.intrinsics().height());
    }
  }
  EXPECT_EQ(world.cameras()[2].model.distortion().model(),
            geometry::DistortionModel::kRadialTangential);
  // The eyes moved between the states, the rig did not (nothing in the scene moves).
  const auto same = [](const Frame& a, const Frame& b) {
    return std::memcmp(a.color->data(), b.color->data(), a.color->size_bytes()) == 0;
  };
  EXPECT_FALSE(same(got[0][0], got[1][0]));
  EXPECT_FALSE(same(got[1][1], got[2][1]));
  EXPECT_TRUE(same(got[0][2], got[2][2]));
}

TEST(RendererTest, SameStateRendersBitIdenticalImages) {
  const scene::Scene world = RichScene();
  RendererOptions options;
  options.msaa_samples = 4;
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  scene::SceneState state = world.InitialState();
  state.joints[0] = 0.2;
  const std::vector<Frame> first = renderer->Render(state, 0);
  const std::vector<Frame> second = renderer->Render(state, 1);
  const std::vector<Frame> other = MakeRenderer(world, options)->Render(state, 0);
  for (std::size_t c = 0; c < first.size(); ++c) {
    ASSERT_EQ(first[c].color->size_bytes(), second[c].color->size_bytes());
    EXPECT_EQ(
        std::memcmp(first[c].color->data(), second[c].color->data(), first[c].color->size_bytes()),
        0)
        << "camera " << c << ", same renderer";
    EXPECT_EQ(
        std::memcmp(first[c].color->data(), other[c].color->data(), first[c].color->size_bytes()),
        0)
        << "camera " << c << ", another renderer";
  }
}

TEST(RendererTest, FramesStayValidWhileTheRendererGoesOn) {
  // The renderer reuses image memory only once the caller has let go of it.
  const scene::Scene world = RichScene();
  RendererOptions options;
  options.cameras = {"rig"};
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  scene::SceneState state = world.InitialState();
  const std::vector<Frame> kept = renderer->Render(state, 0);
  const std::vector<uint8_t> copy(kept[0].color->data(),
                                  kept[0].color->data() + kept[0].color->size_bytes());
  for (int i = 1; i < 6; ++i) {
    state.joints[0] = 0.1 * i;
    const std::vector<Frame> frames = renderer->Render(state, i);
    EXPECT_NE(frames[0].color.get(), kept[0].color.get());
    EXPECT_EQ(frames[0].color->metadata().frame_index, i);
  }
  EXPECT_EQ(kept[0].color->metadata().frame_index, 0);
  EXPECT_EQ(std::memcmp(copy.data(), kept[0].color->data(), copy.size()), 0);
}

TEST(RendererTest, DrawRobotOptionShowsOrHidesTheHead) {
  const scene::Scene world = RichScene();
  RendererOptions with, without;
  with.cameras = without.cameras = {"rig"};
  without.draw_robot = false;
  const Image a = *MakeRenderer(world, with)->Render(world.InitialState(), 0)[0].color;
  const Image b = *MakeRenderer(world, without)->Render(world.InitialState(), 0)[0].color;
  // The head's base box (below X_WB) is in the rig's view: the images differ there only.
  const geometry::Pose X_WB = world.robot()->head.X_WB();
  const scene::CameraSpec& rig = world.cameras()[2];
  const Vector3d p_W = X_WB * Vector3d(0, 0, -0.3);
  const std::optional<Vector2d> uv =
      geometry::CameraModel(rig.model.intrinsics()).Project(rig.X_WC.inverse() * p_W);
  ASSERT_TRUE(uv.has_value());
  ASSERT_TRUE(rig.model.intrinsics().width() > uv->x() && uv->x() > 0 &&
              rig.model.intrinsics().height() > uv->y() && uv->y() > 0)
      << "the head's base should be in the rig's view";
  const int u = static_cast<int>(std::lround(uv->x())), v = static_cast<int>(std::lround(uv->y()));
  const Rgb robot = PixelAt(a, u, v), none = PixelAt(b, u, v);
  EXPECT_TRUE(robot.r != none.r || robot.g != none.g || robot.b != none.b);
}

TEST(RendererTest, CamerasOptionSelectsAndOrdersCameras) {
  const scene::Scene world = RichScene();
  RendererOptions options;
  options.cameras = {"rig", "left"};
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  EXPECT_EQ(renderer->camera_names(), (std::vector<std::string>{"rig", "left"}));
  const std::vector<Frame> frames = renderer->Render(world.InitialState(), 0);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].color->metadata().camera, "rig");
  EXPECT_EQ(frames[1].color->metadata().camera, "left");
  EXPECT_NE(renderer->DeviceDescription().find("OpenGL"), std::string::npos)
      << renderer->DeviceDescription();
}

TEST(RendererTest, InvalidOptionsThrowInvalidArgumentNamingTheOption) {
  const scene::Scene world = RichScene();
  const auto expect_invalid = [&world](const RendererOptions& options,
                                       const std::vector<std::string>& words) {
    std::string error;
    try {
      MakeRenderer(world, options);
      ADD_FAILURE() << "no exception";
    } catch (const InvalidArgument& e) {
      error = e.what();
    }
    for (const std::string& word : words) {
      EXPECT_NE(error.find(word), std::string::npos) << "'" << word << "' not in: " << error;
    }
  };
  RendererOptions msaa;
  msaa.msaa_samples = 3;
  std::string why;
  EXPECT_FALSE(msaa.IsValid(&why));
  EXPECT_NE(why.find("msaa_samples"), std::string::npos) << why;
  expect_invalid(msaa, {"MakeRenderer", "msaa_samples", "3", "0", "2", "4", "8"});
  msaa.msaa_samples = -1;
  expect_invalid(msaa, {"msaa_samples", "-1"});

  RendererOptions unknown;
  unknown.cameras = {"left", "nope"};
  expect_invalid(unknown, {"MakeRenderer", "cameras", "\"nope\"", "\"left\"", "\"rig\""});
  RendererOptions twice;
  twice.cameras = {"left", "left"};
  EXPECT_FALSE(twice.IsValid(nullptr));
  expect_invalid(twice, {"cameras", "\"left\"", "twice"});
  RendererOptions empty_name;
  empty_name.cameras = {""};
  expect_invalid(empty_name, {"cameras", "empty"});

  EXPECT_TRUE(RendererOptions().IsValid(nullptr));
  for (int samples : {0, 2, 4, 8}) {
    RendererOptions ok;
    ok.msaa_samples = samples;
    EXPECT_TRUE(ok.IsValid(&why)) << samples;
    EXPECT_EQ(why, "");
  }
}

TEST(RendererTest, SceneWithoutCamerasIsRejected) {
  const scene::Scene world(Vector3f::Zero(), {}, NoGround(), {}, {}, std::nullopt);
  EXPECT_THROW(MakeRenderer(world), InvalidArgument);
}

TEST(RendererTest, MsaaBeyondTheDeviceIsClampedAndSaid) {
  const scene::Scene world(Vector3f::Zero(), {Ambient(1.0f)}, NoGround(), {},
                           {WorldCamera("cam", kVga, geometry::Pose::Identity())}, std::nullopt);
  RendererOptions options;
  options.msaa_samples = 8;
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  EXPECT_NE(renderer->DeviceDescription().find("MSAA"), std::string::npos)
      << renderer->DeviceDescription();
  EXPECT_EQ(renderer->Render(world.InitialState(), 0).size(), 1u);
}

TEST(RendererTest, RenderWithAStateInFlightThrows) {
  const scene::Scene world(Vector3f::Zero(), {Ambient(1.0f)}, NoGround(), {},
                           {WorldCamera("cam", kVga, geometry::Pose::Identity())}, std::nullopt);
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world);
  renderer->Submit(world.InitialState(), 0);
  EXPECT_THROW(renderer->Render(world.InitialState(), 1), Error);
  EXPECT_EQ(renderer->Retrieve()[0].color->metadata().frame_index, 0);
  EXPECT_EQ(renderer->Render(world.InitialState(), 1)[0].color->metadata().frame_index, 1);
}

TEST(RendererTest, TwoRenderersTakeTurnsOnOneThread) {
  const scene::Scene red(Vector3f(1, 0, 0), {}, NoGround(), {},
                         {WorldCamera("cam", kVga, geometry::Pose::Identity())}, std::nullopt);
  const scene::Scene blue(Vector3f(0, 0, 1), {}, NoGround(), {},
                          {WorldCamera("cam", kVga, geometry::Pose::Identity())}, std::nullopt);
  const std::unique_ptr<Renderer> a = MakeRenderer(red);
  const std::unique_ptr<Renderer> b = MakeRenderer(blue);
  for (int i = 0; i < 2; ++i) {
    ExpectColor(PixelAt(*a->Render(red.InitialState(), i)[0].color, 5, 5), Vector3f(1, 0, 0),
                "first renderer");
    ExpectColor(PixelAt(*b->Render(blue.InitialState(), i)[0].color, 5, 5), Vector3f(0, 0, 1),
                "second renderer");
  }
}

TEST(RendererTest, EglDeviceOverrideIsCheckedAndNamed) {
  // SACCADE_EGL_DEVICE picks the EGL display (internal_egl_context.h); a bad value is an Error
  // that names the variable and the value.
  const scene::Scene world(Vector3f::Zero(), {}, NoGround(), {},
                           {WorldCamera("cam", kVga, geometry::Pose::Identity())}, std::nullopt);
  ASSERT_EQ(setenv("SACCADE_EGL_DEVICE", "99", 1), 0);
  std::string error;
  try {
    MakeRenderer(world);
  } catch (const Error& e) {
    error = e.what();
  }
  ASSERT_EQ(setenv("SACCADE_EGL_DEVICE", "surfaceless", 1), 0);
  std::string description;
  try {
    description = MakeRenderer(world)->DeviceDescription();
  } catch (const Error& e) {
    description = e.what();  // no Mesa surfaceless platform here: the error says so
  }
  ASSERT_EQ(unsetenv("SACCADE_EGL_DEVICE"), 0);
  EXPECT_NE(error.find("SACCADE_EGL_DEVICE"), std::string::npos) << error;
  EXPECT_NE(error.find("\"99\""), std::string::npos) << error;
  EXPECT_NE(description.find("surfaceless"), std::string::npos) << description;
}

}  // namespace
}  // namespace saccade::render
