// Scene files: what a valid file gives, and the message of every kind of bad input (file,
// line, key path, what was expected).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "saccade/core/error.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/scene/limits.h"
#include "saccade/scene/scene.h"
#include "scene/scene_test_util.h"

namespace saccade::scene {
namespace {

using testing::ExpectMessageHas;
using testing::LineOf;
using testing::LoadError;
using testing::Replace;
using testing::TempDir;

constexpr double kDeg = std::numbers::pi / 180.0;
// Values read from YAML go through at most a multiplication (deg -> rad): a few ulps.
constexpr double kParseTolerance = 1e-12;

// A tetrahedron: 4 vertices, 4 triangles.
const char* const kTetrahedron = R"(v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
)";

// A valid scene using every section; tests break one entry at a time. Files live in a
// temporary folder: photo.png (40 x 20), tetra.obj, and the POPEYE head description.
const std::string kValid = R"(background: [0.1, 0.2, 0.3]
lights:
  - type: ambient
    intensity: 0.25
  - type: directional
    direction: [0, 0, -2]
    color: [1, 0.9, 0.8]
  - type: point
    position: [1, 2, 3]
    attenuation: 0.5
ground:
  size: 8
  pattern: checker
  cell: 0.25
  color: [0.9, 0.9, 0.9]
  color2: [0.1, 0.1, 0.1]
objects:
  - name: photo
    kind: picture
    image: photo.png
    height: 0.5
    pose:
      position: [2, 0, 1.2]
      rpy_deg: [0, 0, 180]
  - name: tetra
    kind: model
    file: tetra.obj
    unit_scale: 0.1
    scale: [1, 2, 3]
    pose:
      position: [1, 1, 0]
  - name: crate
    kind: box
    size: [0.2, 0.3, 0.4]
    color: [0.5, 0.4, 0.3, 1.0]
    pose:
      position: [1, -1, 0.2]
      rpy: [0, 0, 0.5]
  - name: ball
    kind: sphere
    radius: 0.1
    motion:
      type: waypoints
      loop: true
      waypoints:
        - {time: 0, position: [1, 0, 1]}
        - {time: 2, position: [1, 1, 1], rpy_deg: [0, 0, 90]}
  - name: mat
    kind: plane
    size: 0.5
    motion:
      type: constant_velocity
      linear: [0.1, 0, 0]
      angular_deg: [0, 0, 10]
robot:
  head: popeye.yaml
  joints_deg: [10, -5, -3, 3]
  visible: false
cameras:
  - name: rig
    calibration: {width: 640, height: 480, fx: 500, fy: 510, cx: 320, cy: 240}
    look_at: {eye: [0, -2, 2], target: [2, 0, 1]}
    clip: {near: 0.1, far: 20}
  - name: top
    calibration:
      width: 320
      height: 240
      focal_length_mm: 4
      pixel_size_um: 5
      distortion: {model: radtan, coefficients: [-0.1, 0.01, 0.001, -0.001]}
    pose:
      position: [0, 0, 5]
      rpy_deg: [180, 0, 0]
)";

class SceneLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Image photo(40, 20, PixelFormat::kRgb8);
    WritePng(photo.view(), dir_.path() / "photo.png");
    dir_.Write("tetra.obj", kTetrahedron);
    std::filesystem::copy_file(testing::kPopeye, dir_.path() / "popeye.yaml");
  }

  Scene Load(const std::string& text) const {
    return Scene::FromYamlString(text, "test.yaml", dir_.path());
  }
  // The error of `text`, expecting "test.yaml:<line of needle>: <key>: ..." and `parts`.
  void ExpectError(const std::string& text, const std::string& needle, const std::string& key,
                   std::initializer_list<std::string> parts) const {
    const FileError error = LoadError(text, dir_.path());
    EXPECT_EQ(error.file(), "test.yaml") << error.what();
    EXPECT_EQ(error.line(), LineOf(text, needle)) << error.what();
    EXPECT_EQ(error.key(), key) << error.what();
    ExpectMessageHas(error, parts);
    ExpectMessageHas(error, {"test.yaml:" + std::to_string(LineOf(text, needle)) + ": " + key});
  }

  TempDir dir_;
};

TEST_F(SceneLoaderTest, ValidSceneLoadsEverySection) {
  const Scene scene = Load(kValid);
  EXPECT_TRUE(scene.background().isApprox(Eigen::Vector3f(0.1f, 0.2f, 0.3f)));
  ASSERT_EQ(scene.lights().size(), 3u);
  EXPECT_EQ(scene.lights()[0].type, Light::Type::kAmbient);
  EXPECT_FLOAT_EQ(scene.lights()[0].intensity, 0.25f);
  EXPECT_EQ(scene.lights()[1].type, Light::Type::kDirectional);
  EXPECT_TRUE(scene.lights()[1].direction_W.isApprox(Eigen::Vector3d(0, 0, -1)));  // normalised
  EXPECT_EQ(scene.lights()[2].type, Light::Type::kPoint);
  EXPECT_EQ(scene.lights()[2].position_W, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(scene.lights()[2].attenuation, 0.5);

  EXPECT_EQ(scene.ground().pattern, Ground::Pattern::kChecker);
  EXPECT_EQ(scene.ground().size, 8.0);
  EXPECT_EQ(scene.ground().cell, 0.25);

  ASSERT_EQ(scene.objects().size(), 5u);
  const auto& objects = scene.objects();
  // Ids 1..N in file order, the robot next.
  for (std::size_t i = 0; i < objects.size(); ++i) EXPECT_EQ(objects[i].id, i + 1);
  ASSERT_TRUE(scene.robot().has_value());
  EXPECT_EQ(scene.robot()->id, 6u);

  // The picture: 40 x 20 pixels, 0.5 m high -> 1 m wide; turned to face -x.
  const Model& photo = *objects[0].model;
  EXPECT_NEAR(photo.bounds.sizes().y(), 1.0f, 1e-6f);
  EXPECT_NEAR(photo.bounds.sizes().z(), 0.5f, 1e-6f);
  const geometry::Pose X_WPhoto = scene.ObjectPose(objects[0], scene.InitialState());
  EXPECT_TRUE((X_WPhoto.linear() * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(X_WPhoto.translation().isApprox(Eigen::Vector3d(2, 0, 1.2)));

  // The model: the unit scale times the object's scale.
  EXPECT_TRUE(objects[1].scale.isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_EQ(objects[1].model->meshes.size(), 1u);
  EXPECT_EQ(objects[1].model->meshes[0].indices.size(), 12u);

  // Primitives: the size is the object's scale of the unit primitive.
  EXPECT_EQ(objects[2].model->source, "box");
  EXPECT_TRUE(objects[2].scale.isApprox(Eigen::Vector3d(0.2, 0.3, 0.4)));
  EXPECT_TRUE(
      objects[2].model->materials[0].base_color.isApprox(Eigen::Vector4f(0.5, 0.4, 0.3, 1)));
  EXPECT_NEAR(geometry::RpyFromRotation(scene.ObjectPose(objects[2], {}).linear()).z(), 0.5,
              kParseTolerance);
  EXPECT_TRUE(objects[3].scale.isApprox(Eigen::Vector3d::Constant(0.2)));  // radius 0.1
  EXPECT_TRUE(objects[4].scale.isApprox(Eigen::Vector3d(0.5, 0.5, 1.0)));

  // Motions.
  EXPECT_FALSE(objects[3].motion.IsStatic());
  SceneState state;
  state.time = 1.0;
  EXPECT_TRUE(
      scene.ObjectPose(objects[3], state).translation().isApprox(Eigen::Vector3d(1, 0.5, 1)));
  state.time = 2.0;  // the loop's period: back to the start
  EXPECT_TRUE(scene.ObjectPose(objects[3], state).translation().isApprox(Eigen::Vector3d(1, 0, 1)));
  state.time = 3.0;
  EXPECT_TRUE(
      scene.ObjectPose(objects[4], state).translation().isApprox(Eigen::Vector3d(0.3, 0, 0)));
  EXPECT_NEAR(geometry::RpyFromRotation(scene.ObjectPose(objects[4], state).linear()).z(),
              30 * kDeg, kParseTolerance);

  // The robot.
  EXPECT_FALSE(scene.robot()->visible);
  EXPECT_NEAR(scene.robot()->initial_joints[0], 10 * kDeg, kParseTolerance);
  EXPECT_NEAR(scene.robot()->initial_joints[1], -5 * kDeg, kParseTolerance);
  EXPECT_NEAR(scene.robot()->initial_joints[2], -3 * kDeg, kParseTolerance);
  EXPECT_NEAR(scene.robot()->initial_joints[3], 3 * kDeg, kParseTolerance);
  EXPECT_EQ(scene.InitialState().joints, scene.robot()->initial_joints);
  EXPECT_EQ(scene.InitialState().time, 0.0);
  EXPECT_FALSE(scene.robot()->parts.empty());
  // The description's servo mapping survives the scene's pose and calibrations (hw.head).
  for (int j = 0; j < 4; ++j) ASSERT_TRUE(scene.robot()->head.joint(j).servo.has_value());
  EXPECT_EQ(scene.robot()->head.joint(1).servo->direction, -1);

  // Cameras: the eyes first, then the file's, in order.
  ASSERT_EQ(scene.cameras().size(), 4u);
  EXPECT_EQ(scene.cameras()[0].name, "left");
  EXPECT_EQ(scene.cameras()[0].mount, CameraMount::kLeftEye);
  EXPECT_EQ(scene.cameras()[1].name, "right");
  EXPECT_EQ(scene.cameras()[1].mount, CameraMount::kRightEye);
  EXPECT_EQ(scene.cameras()[0].model, scene.robot()->head.camera(0).model);
  const CameraSpec* rig = scene.FindCamera("rig");
  ASSERT_NE(rig, nullptr);
  EXPECT_EQ(rig->mount, CameraMount::kWorld);
  EXPECT_EQ(rig->model.intrinsics(), geometry::Intrinsics(640, 480, 500, 510, 320, 240));
  EXPECT_EQ(rig->clip.near, 0.1);
  EXPECT_EQ(rig->clip.far, 20.0);
  const CameraSpec* top = scene.FindCamera("top");
  ASSERT_NE(top, nullptr);
  EXPECT_NEAR(top->model.intrinsics().fx(), 800.0, kParseTolerance);  // 4 mm / 5 um
  EXPECT_EQ(top->model.intrinsics().cx(), 159.5);                     // (320 - 1) / 2
  EXPECT_EQ(top->model.distortion().model(), geometry::DistortionModel::kRadialTangential);
  EXPECT_EQ(top->clip.near, 0.05);  // defaults
  EXPECT_EQ(top->clip.far, 50.0);
  // Looking straight down: the optical axis is -z.
  EXPECT_TRUE((top->X_WC.linear() * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(scene.FindCamera("nope"), nullptr);
}

TEST_F(SceneLoaderTest, DefaultsForAnEmptyMap) {
  const Scene scene = Load("{}");
  EXPECT_TRUE(scene.objects().empty());
  EXPECT_TRUE(scene.cameras().empty());
  EXPECT_FALSE(scene.robot().has_value());
  EXPECT_EQ(scene.lights().size(), 2u);  // ambient + directional
  EXPECT_TRUE(scene.ground().enabled);
  EXPECT_EQ(scene.ground().pattern, Ground::Pattern::kGrid);
  EXPECT_TRUE(scene.models().empty());
  EXPECT_TRUE(Load("lights: []").lights().empty());
}

TEST_F(SceneLoaderTest, ExplicitIdsAreKeptAndTheOthersTakeTheSmallestFreeOnes) {
  const std::string text = R"(objects:
  - {name: a, kind: box, size: 1}
  - {name: b, kind: box, size: 1, id: 1}
  - {name: c, kind: box, size: 1}
  - {name: d, kind: box, size: 1, id: 3}
robot: {head: popeye.yaml}
)";
  const Scene scene = Load(text);
  EXPECT_EQ(scene.objects()[0].id, 2u);
  EXPECT_EQ(scene.objects()[1].id, 1u);
  EXPECT_EQ(scene.objects()[2].id, 4u);
  EXPECT_EQ(scene.objects()[3].id, 3u);
  EXPECT_EQ(scene.robot()->id, 5u);
  const Scene with_robot_id =
      Load(Replace(text, "{head: popeye.yaml}", "{head: popeye.yaml, id: 2}"));
  EXPECT_EQ(with_robot_id.robot()->id, 2u);
  EXPECT_EQ(with_robot_id.objects()[0].id, 4u);
  EXPECT_EQ(with_robot_id.objects()[2].id, 5u);
}

TEST_F(SceneLoaderTest, PrimitivesOfOneColourShareAModel) {
  const Scene scene = Load(R"(objects:
  - {name: a, kind: box, size: 1, color: [1, 0, 0]}
  - {name: b, kind: box, size: 2, color: [1, 0, 0]}
  - {name: c, kind: box, size: 1, color: [0, 1, 0]}
)");
  EXPECT_EQ(scene.objects()[0].model, scene.objects()[1].model);
  EXPECT_NE(scene.objects()[0].model, scene.objects()[2].model);
  EXPECT_EQ(scene.models().size(), 2u);
}

TEST_F(SceneLoaderTest, LoadResolvesPathsAgainstTheScenesFolder) {
  const auto path = dir_.Write("sub/../scene.yaml", kValid);
  const Scene scene = Scene::Load(path);
  EXPECT_EQ(scene.objects().size(), 5u);
  // A missing scene file names itself.
  try {
    Scene::Load(dir_.path() / "missing.yaml");
    ADD_FAILURE() << "loaded a missing file";
  } catch (const FileError& error) {
    ExpectMessageHas(error, {"missing.yaml", "not found"});
  }
  EXPECT_THROW(Scene::Load(dir_.path()), FileError);  // a folder
}

// --- Bad input: one test per kind, each checking file, line, key and what. ---------------

TEST_F(SceneLoaderTest, SyntaxErrorNamesTheLine) {
  const std::string text = Replace(kValid, "  size: 8\n", "  size: [8\n");
  const FileError error = LoadError(text, dir_.path());
  EXPECT_GT(error.line(), 0);
  ExpectMessageHas(error, {"test.yaml:", "YAML syntax error"});
}

TEST_F(SceneLoaderTest, EmptyFileOrNotAMap) {
  ExpectMessageHas(LoadError("", dir_.path()), {"test.yaml", "expected a scene", "got nothing"});
  ExpectMessageHas(LoadError("- 1\n- 2\n", dir_.path()), {"expected a scene", "a list of 2"});
}

TEST_F(SceneLoaderTest, UnknownKeys) {
  ExpectError(kValid + "objectz: []\n", "objectz", "objectz", {"unknown key 'objectz'", "objects"});
  ExpectError(Replace(kValid, "    height: 0.5\n", "    height: 0.5\n    heigth: 2\n"), "heigth",
              "objects[0].heigth", {"unknown key 'heigth'", "height"});
  // A key of another kind of object.
  ExpectError(Replace(kValid, "    radius: 0.1\n", "    radius: 0.1\n    size: 2\n"), "    size: 2",
              "objects[3].size", {"unknown key 'size'", "radius"});
}

TEST_F(SceneLoaderTest, DuplicateKeys) {
  ExpectError(Replace(kValid, "  size: 8\n", "  size: 8\n  size: 9\n"), "size: 9", "ground.size",
              {"duplicate key 'size'"});
}

TEST_F(SceneLoaderTest, MissingRequiredKeys) {
  ExpectError(Replace(kValid, "    kind: box\n", ""), "name: crate", "objects[2]",
              {"missing key 'kind'"});
  ExpectError(Replace(kValid, "    height: 0.5\n", ""), "name: photo", "objects[0]",
              {"missing key 'height'"});
  ExpectError(Replace(kValid, "    direction: [0, 0, -2]\n", ""), "type: directional", "lights[1]",
              {"missing key 'direction'"});
  ExpectError(Replace(kValid, "  head: popeye.yaml\n", ""), "joints_deg", "robot",
              {"missing key 'head'"});
}

TEST_F(SceneLoaderTest, WrongTypesAndLengths) {
  ExpectError(Replace(kValid, "position: [1, -1, 0.2]", "position: [1, -1]"), "position: [1, -1]",
              "objects[2].pose.position", {"expected 3 numbers", "got 2"});
  ExpectError(Replace(kValid, "position: [1, -1, 0.2]", "position: one"), "position: one",
              "objects[2].pose.position", {"expected 3 numbers", "got 'one'"});
  ExpectError(Replace(kValid, "position: [1, -1, 0.2]", "position: [1, x, 0.2]"), "position: [1, x",
              "objects[2].pose.position[1]", {"expected a number", "'x'"});
  ExpectError(Replace(kValid, "  visible: false", "  visible: maybe"), "visible: maybe",
              "robot.visible", {"expected true or false"});
  ExpectError("objects: {a: 1}\n", "objects", "objects", {"expected a list of objects", "a map"});
  ExpectError(Replace(kValid, "    kind: box\n", "    kind: cube\n"), "kind: cube",
              "objects[2].kind",
              {"expected 'model', 'picture', 'box', 'sphere' or 'plane'", "'cube'"});
  ExpectError(Replace(kValid, "pattern: checker", "pattern: stripes"), "pattern: stripes",
              "ground.pattern", {"'plain', 'grid' or 'checker'", "'stripes'"});
  ExpectError(Replace(kValid, "type: point", "type: spot"), "type: spot", "lights[2].type",
              {"'ambient', 'directional' or 'point'", "'spot'"});
}

TEST_F(SceneLoaderTest, NonFiniteNumbers) {
  ExpectError(Replace(kValid, "position: [1, -1, 0.2]", "position: [1, .nan, 0.2]"),
              "position: [1, .nan", "objects[2].pose.position[1]", {"expected a finite number"});
  ExpectError(Replace(kValid, "    height: 0.5", "    height: .inf"), "height: .inf",
              "objects[0].height", {"expected a finite number"});
  ExpectError(Replace(kValid, "scale: [1, 2, 3]", "scale: [1, -.inf, 3]"), "scale: [1, -.inf",
              "objects[1].scale[1]", {"expected a finite number"});
  ExpectError(Replace(kValid, "attenuation: 0.5", "attenuation: .NaN"), "attenuation: .NaN",
              "lights[2].attenuation", {"expected a finite number"});
  ExpectError(Replace(kValid, "{time: 2,", "{time: .inf,"), "{time: .inf",
              "objects[3].motion.waypoints[1].time", {"expected a finite number"});
}

TEST_F(SceneLoaderTest, NonPositiveSizes) {
  ExpectError(Replace(kValid, "scale: [1, 2, 3]", "scale: [1, 0, 3]"), "scale: [1, 0",
              "objects[1].scale[1]", {"expected a positive number", "got 0"});
  ExpectError(Replace(kValid, "scale: [1, 2, 3]", "scale: -2"), "scale: -2", "objects[1].scale",
              {"expected a positive number", "-2"});
  ExpectError(Replace(kValid, "scale: [1, 2, 3]", "scale: [1, 2]"), "scale: [1, 2]",
              "objects[1].scale", {"3 positive numbers", "got 2 numbers"});
  ExpectError(Replace(kValid, "size: [0.2, 0.3, 0.4]", "size: [0.2, 0.0, 0.4]"), "size: [0.2, 0.0",
              "objects[2].size[1]", {"expected a positive number"});
  ExpectError(Replace(kValid, "radius: 0.1", "radius: -0.1"), "radius: -0.1", "objects[3].radius",
              {"expected a positive number", "-0.1"});
  ExpectError(Replace(kValid, "    height: 0.5", "    height: 0"), "height: 0", "objects[0].height",
              {"expected a positive number"});
  // Finite as a double, not as the float a vertex holds (found by the scene fuzzer).
  ExpectError(Replace(kValid, "    height: 0.5", "    height: 1e300"), "height: 1e300",
              "objects[0].height", {"at most 1e+06 m a side", "1e+300 m"});
  ExpectError(Replace(kValid, "unit_scale: 0.1", "unit_scale: 0"), "unit_scale: 0",
              "objects[1].unit_scale", {"expected a positive number"});
  ExpectError(Replace(kValid, "  size: 8\n", "  size: -8\n"), "size: -8", "ground.size",
              {"expected a positive number"});
  ExpectError(Replace(kValid, "  cell: 0.25\n", "  cell: 0.25\n  line_width: 0.3\n"),
              "line_width: 0.3", "ground.line_width", {"line_width < cell"});
  ExpectError(Replace(kValid, "intensity: 0.25", "intensity: -1"), "intensity: -1",
              "lights[0].intensity", {"expected a number >= 0"});
  ExpectError(Replace(kValid, "direction: [0, 0, -2]", "direction: [0, 0, 0]"), "direction: [0",
              "lights[1].direction", {"non-zero direction"});
}

TEST_F(SceneLoaderTest, ColoursOutsideTheUnitRange) {
  ExpectError(Replace(kValid, "background: [0.1, 0.2, 0.3]", "background: [0.1, 2, 0.3]"),
              "background", "background[1]", {"each in [0, 1]", "got 2"});
  ExpectError(Replace(kValid, "background: [0.1, 0.2, 0.3]", "background: [0.1, 0.2, 0.3, 1]"),
              "background", "background", {"expected a colour [r, g, b]", "got 4 numbers"});
  ExpectError(Replace(kValid, "color: [0.5, 0.4, 0.3, 1.0]", "color: [0.5, 0.4]"),
              "color: [0.5, 0.4]", "objects[2].color", {"[r, g, b] or [r, g, b, a]"});
}

TEST_F(SceneLoaderTest, DuplicateNamesAndIds) {
  ExpectError(Replace(kValid, "name: crate", "name: tetra"), "name: tetra\n    kind: box",
              "objects[2].name", {"duplicate object name 'tetra'", "objects[1]"});
  const std::string ids = R"(objects:
  - {name: a, kind: box, size: 1, id: 4}
  - {name: b, kind: box, size: 1, id: 4}
)";
  ExpectError(ids, "{name: b", "objects[1].id", {"duplicate id 4", "objects[0] 'a'"});
  ExpectError(Replace(ids, "id: 4}\n  - {name: b", "id: 0}\n  - {name: b"), "id: 0",
              "objects[0].id", {"expected an integer in [1, 16777215]", "'0'"});
  const std::string robot_id = Replace(ids, "id: 4}\n  - {name: b, kind: box, size: 1, id: 4}",
                                       "id: 4}\nrobot: {head: popeye.yaml, id: 4}");
  ExpectError(robot_id, "robot:", "robot.id", {"duplicate id 4", "objects[0] 'a'"});
  ExpectError(Replace(kValid, "name: top", "name: rig"), "name: rig\n    calibration:\n",
              "cameras[1].name", {"duplicate camera name 'rig'", "cameras[0]"});
  ExpectError(Replace(kValid, "name: top", "name: left"), "name: left", "cameras[1].name",
              {"duplicate camera name 'left'", "the robot's left eye camera"});
  ExpectError(Replace(kValid, "name: top", "name: ../top"), "name: ../top", "cameras[1].name",
              {"letters, digits"});
}

TEST_F(SceneLoaderTest, MissingFilesNameTheKeyAndThePath) {
  const auto expect_missing = [&](const std::string& from, const std::string& to,
                                  const std::string& key, const std::string& what) {
    const std::string text = Replace(kValid, from, to);
    ExpectError(text, to, key,
                {what + " not found", "'" + to.substr(to.find(": ") + 2) + "'",
                 (dir_.path() / "nothere").string()});
  };
  expect_missing("image: photo.png", "image: nothere.png", "objects[0].image", "image");
  expect_missing("file: tetra.obj", "file: nothere.obj", "objects[1].file", "model file");
  expect_missing("head: popeye.yaml", "head: nothere.yaml", "robot.head", "head description");
  const std::string calibration =
      Replace(kValid, "calibration: {width: 640, height: 480, fx: 500, fy: 510, cx: 320, cy: 240}",
              "calibration: nothere_calib.yaml");
  ExpectError(calibration, "nothere_calib", "cameras[0].calibration",
              {"calibration file not found", "nothere_calib.yaml"});
  // A folder is not a file.
  std::filesystem::create_directory(dir_.path() / "folder.png");
  ExpectError(Replace(kValid, "image: photo.png", "image: folder.png"), "image: folder.png",
              "objects[0].image", {"not a regular file"});
}

TEST_F(SceneLoaderTest, UnreadableReferencedFilesGiveTheirOwnErrorBehindTheKey) {
  dir_.Write("bad.png", "not a png");
  ExpectError(Replace(kValid, "image: photo.png", "image: bad.png"), "image: bad.png",
              "objects[0].image",
              {"cannot read image 'bad.png'", "bad.png", "not a readable image"});
  dir_.Write("bad_head.yaml", "name: x\n");
  ExpectError(Replace(kValid, "head: popeye.yaml", "head: bad_head.yaml"), "head: bad_head",
              "robot.head",
              {"cannot load head description 'bad_head.yaml'", "bad_head.yaml:", "missing key"});
  dir_.Write("bad_calib.yaml", "%YAML:1.0\nimage_width: 640\n");
  ExpectError(
      Replace(kValid, "calibration: {width: 640, height: 480, fx: 500, fy: 510, cx: 320, cy: 240}",
              "calibration: bad_calib.yaml"),
      "bad_calib", "cameras[0].calibration",
      {"cannot read calibration 'bad_calib.yaml'", "bad_calib.yaml"});
}

TEST_F(SceneLoaderTest, AnglesGivenTwiceOrJointsOutsideTheirLimits) {
  ExpectError(
      Replace(kValid, "      rpy: [0, 0, 0.5]", "      rpy: [0, 0, 0.5]\n      rpy_deg: [0, 0, 1]"),
      "rpy_deg: [0, 0, 1]", "objects[2].pose.rpy_deg", {"either 'rpy'", "not both"});
  ExpectError(Replace(kValid, "joints_deg: [10, -5, -3, 3]", "joints_deg: [100, -5, -3, 3]"),
              "joints_deg", "robot.joints_deg", {"joint pan", "outside its limits"});
  ExpectError(Replace(kValid, "joints_deg: [10, -5, -3, 3]", "joints_deg: [10, -5, -3]"),
              "joints_deg", "robot.joints_deg", {"expected 4 numbers [pan, tilt, left, right]"});
}

TEST_F(SceneLoaderTest, BadMotions) {
  ExpectError(Replace(kValid, "{time: 2,", "{time: 0,"), "{time: 0, position: [1, 1",
              "objects[3].motion.waypoints[1].time", {"after the previous waypoint's (0 s)"});
  ExpectError(Replace(kValid, "{time: 0, position: [1, 0, 1]}", "{time: -1, position: [1, 0, 1]}"),
              "time: -1", "objects[3].motion.waypoints[0].time", {"expected a number >= 0"});
  ExpectError(
      Replace(kValid, "    radius: 0.1\n", "    radius: 0.1\n    pose: {position: [0, 0, 0]}\n"),
      "pose: {position: [0, 0, 0]}", "objects[3].pose", {"either 'pose' or a waypoint motion"});
  // One waypoint at time 0: a loop of period 0.
  ExpectError(
      Replace(kValid, "        - {time: 2, position: [1, 1, 1], rpy_deg: [0, 0, 90]}\n", ""),
      "loop: true", "objects[3].motion.loop", {"a loop needs the last waypoint's time"});
  ExpectError(Replace(kValid, "type: waypoints", "type: spline"), "type: spline",
              "objects[3].motion.type", {"'waypoints' or 'constant_velocity'"});
  ExpectError(Replace(kValid,
                      "      waypoints:\n        - {time: 0, position: [1, 0, 1]}\n"
                      "        - {time: 2, position: [1, 1, 1], rpy_deg: [0, 0, 90]}\n",
                      "      waypoints: []\n"),
              "waypoints: []", "objects[3].motion.waypoints", {"at least one waypoint"});
  ExpectError(Replace(kValid, "linear: [0.1, 0, 0]", "linear: [0.1, 0, 0]\n      loop: true"),
              "      loop: true\n      angular", "objects[4].motion.loop", {"unknown key 'loop'"});
}

TEST_F(SceneLoaderTest, BadCameras) {
  ExpectError(Replace(kValid, "look_at: {eye: [0, -2, 2], target: [2, 0, 1]}",
                      "look_at: {eye: [0, -2, 2], target: [0, -2, 2]}"),
              "look_at", "cameras[0].look_at.target", {"apart from the eye"});
  ExpectError(Replace(kValid, "look_at: {eye: [0, -2, 2], target: [2, 0, 1]}",
                      "look_at: {eye: [0, 0, 2], target: [0, 0, 0]}"),
              "look_at", "cameras[0].look_at", {"not parallel"});
  ExpectError(Replace(kValid, "    look_at: {eye: [0, -2, 2], target: [2, 0, 1]}\n", ""),
              "- name: rig", "cameras[0]", {"give 'pose' or 'look_at'"});
  ExpectError(
      Replace(kValid, "look_at: {eye: [0, -2, 2], target: [2, 0, 1]}",
              "look_at: {eye: [0, -2, 2], target: [2, 0, 1]}\n    pose: {position: [0, 0, 0]}"),
      "look_at", "cameras[0].look_at", {"either 'pose' or 'look_at'"});
  ExpectError(Replace(kValid, "fx: 500", "fx: -500"), "fx: -500", "cameras[0].calibration.fx",
              {"expected a positive number"});
  ExpectError(Replace(kValid, "model: radtan", "model: pinhole"), "model: pinhole",
              "cameras[1].calibration.distortion.model", {"'none', 'radtan' or 'fisheye'"});
  ExpectError(Replace(kValid, "clip: {near: 0.1, far: 20}", "clip: {near: 2, far: 1}"),
              "clip:", "cameras[0].clip.far", {"near < far"});
  ExpectError(
      Replace(kValid, "calibration: {width: 640, height: 480,", "calibration: {width: 640,"),
      "calibration: {width: 640,", "cameras[0].calibration", {"missing key 'height'"});
}

TEST_F(SceneLoaderTest, CalibrationsFromFilesInEveryFormat) {
  const geometry::CameraModel model(
      geometry::Intrinsics(800, 600, 700.5, 702.25, 401.5, 299.0),
      geometry::Distortion::RadialTangential(std::vector<double>{-0.2, 0.05, 0.001, -0.002, 0.01}));
  const std::pair<const char*, geometry::CalibrationFormat> formats[] = {
      {"calib.yaml", geometry::CalibrationFormat::kOpenCvYaml},
      {"calib.xml", geometry::CalibrationFormat::kOpenCvXml},
      {"ros.yaml", geometry::CalibrationFormat::kRosYaml}};
  for (const auto& [name, format] : formats) {
    geometry::WriteCameraCalibration({model, "cam"}, dir_.path() / name, format);
    const std::string text = Replace(
        Replace(kValid,
                "calibration: {width: 640, height: 480, fx: 500, fy: 510, cx: 320, cy: 240}",
                std::string("calibration: ") + name),
        "  visible: false\n",
        std::string("  visible: false\n  cameras:\n    right:\n") +
            "      calibration: {file: " + name + "}\n" + "      clip: {near: 0.02, far: 10}\n");
    const Scene scene = Load(text);
    const CameraSpec* rig = scene.FindCamera("rig");
    ASSERT_NE(rig, nullptr);
    EXPECT_EQ(rig->model.intrinsics(), model.intrinsics()) << name;
    EXPECT_EQ(rig->model.distortion().model(), model.distortion().model()) << name;
    for (std::size_t k = 0; k < model.distortion().coefficients().size(); ++k) {
      EXPECT_NEAR(rig->model.distortion().coefficients()[k], model.distortion().coefficients()[k],
                  kParseTolerance);
    }
    // The right eye's calibration is replaced, in the camera and in the head description.
    const CameraSpec* right = scene.FindCamera("right");
    ASSERT_NE(right, nullptr);
    EXPECT_EQ(right->model.intrinsics(), model.intrinsics());
    EXPECT_EQ(scene.robot()->head.camera(1).model.intrinsics(), model.intrinsics());
    EXPECT_EQ(right->clip.near, 0.02);
    EXPECT_EQ(scene.FindCamera("left")->model, scene.robot()->head.camera(0).model);
  }
}

TEST_F(SceneLoaderTest, RobotPoseReplacesTheDescriptions) {
  const Scene scene =
      Load(Replace(kValid, "  visible: false\n",
                   "  visible: false\n  pose: {position: [1, 2, 0.5], rpy_deg: [0, 0, 90]}\n"));
  const geometry::Pose& X_WB = scene.robot()->head.X_WB();
  EXPECT_TRUE(X_WB.translation().isApprox(Eigen::Vector3d(1, 2, 0.5)));
  EXPECT_TRUE((X_WB.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  // Without it, the description's (POPEYE: 1.2 m up).
  EXPECT_TRUE(Load(kValid).robot()->head.X_WB().translation().isApprox(Eigen::Vector3d(0, 0, 1.2)));
}

// A sensor block on a world camera and on an eye camera (robot.cameras.left).
std::string WithSensors(const std::string& world_sensor, const std::string& eye_sensor) {
  std::string text = Replace(kValid, "    clip: {near: 0.1, far: 20}\n",
                             "    clip: {near: 0.1, far: 20}\n    sensor:\n" + world_sensor);
  return Replace(text, "  visible: false\n",
                 "  visible: false\n  cameras:\n    left:\n      sensor:\n" + eye_sensor);
}

const std::string kWorldSensor = R"(      exposure: 0.004
      blur_samples: 16
      read_noise_dn: 1.5
      gain_dn_per_e: 0.25
      seed: 18446744073709551615
)";
const std::string kEyeSensor = R"(        exposure_ms: 8
        read_noise_dn: 2
        seed: 42
)";

TEST_F(SceneLoaderTest, SensorBlocksAreReadForWorldAndEyeCameras) {
  const Scene scene = Load(WithSensors(kWorldSensor, kEyeSensor));
  const SensorSpec& rig = scene.FindCamera("rig")->sensor;
  EXPECT_EQ(rig.exposure, 0.004);
  EXPECT_EQ(rig.blur_samples, 16);
  EXPECT_EQ(rig.read_noise_dn, 1.5);
  EXPECT_EQ(rig.gain_dn_per_e, 0.25);
  EXPECT_EQ(rig.seed, UINT64_C(18446744073709551615));  // 2^64 - 1
  EXPECT_TRUE(rig.HasBlur());
  EXPECT_TRUE(rig.HasNoise());
  const SensorSpec& left = scene.FindCamera("left")->sensor;
  EXPECT_NEAR(left.exposure, 0.008, kParseTolerance);  // milliseconds to seconds
  EXPECT_EQ(left.blur_samples, SensorSpec{}.blur_samples);
  EXPECT_EQ(left.read_noise_dn, 2.0);
  EXPECT_EQ(left.gain_dn_per_e, 0.0);
  EXPECT_EQ(left.seed, 42u);
  // Cameras without a block keep the defaults: everything off.
  for (const char* name : {"right", "top"}) {
    const SensorSpec& sensor = scene.FindCamera(name)->sensor;
    EXPECT_FALSE(sensor.HasBlur()) << name;
    EXPECT_FALSE(sensor.HasNoise()) << name;
    EXPECT_EQ(sensor.seed, 0u) << name;
  }
  // The range's ends are allowed; a hexadecimal seed too.
  const Scene ends =
      Load(WithSensors("      exposure: 1\n      blur_samples: 64\n      read_noise_dn: 64\n"
                       "      gain_dn_per_e: 0\n      seed: 0x10\n",
                       "        exposure_ms: 0\n        blur_samples: 1\n        seed: 0\n"));
  EXPECT_EQ(ends.FindCamera("rig")->sensor.exposure, 1.0);
  EXPECT_EQ(ends.FindCamera("rig")->sensor.blur_samples, 64);
  EXPECT_EQ(ends.FindCamera("rig")->sensor.seed, 16u);
  EXPECT_EQ(ends.FindCamera("left")->sensor.exposure, 0.0);
}

TEST_F(SceneLoaderTest, BadSensorsNameTheFileLineAndKey) {
  // World camera: cameras[0].sensor.
  const auto world = [&](const std::string& from, const std::string& to) {
    return WithSensors(Replace(kWorldSensor, from, to), kEyeSensor);
  };
  ExpectError(world("exposure: 0.004", "exposure: -0.004"), "exposure: -0.004",
              "cameras[0].sensor.exposure",
              {"expected an exposure in seconds in [0, 1]", "got '-0.004'"});
  ExpectError(world("exposure: 0.004", "exposure: 2"), "exposure: 2", "cameras[0].sensor.exposure",
              {"in [0, 1]", "got '2'"});
  ExpectError(world("exposure: 0.004\n", "exposure: 0.004\n      exposure_ms: 4\n"),
              "exposure_ms: 4", "cameras[0].sensor.exposure_ms",
              {"either 'exposure' (seconds) or 'exposure_ms', not both"});
  ExpectError(world("blur_samples: 16", "blur_samples: 0"), "blur_samples: 0",
              "cameras[0].sensor.blur_samples", {"expected an integer in [1, 64]", "got '0'"});
  ExpectError(world("blur_samples: 16", "blur_samples: 65"), "blur_samples: 65",
              "cameras[0].sensor.blur_samples", {"expected an integer in [1, 64]", "got '65'"});
  ExpectError(world("blur_samples: 16", "blur_samples: 2.5"), "blur_samples: 2.5",
              "cameras[0].sensor.blur_samples", {"expected an integer in [1, 64]", "got '2.5'"});
  ExpectError(world("read_noise_dn: 1.5", "read_noise_dn: .nan"), "read_noise_dn: .nan",
              "cameras[0].sensor.read_noise_dn", {"expected a finite number", "'.nan'"});
  ExpectError(world("read_noise_dn: 1.5", "read_noise_dn: 65"), "read_noise_dn: 65",
              "cameras[0].sensor.read_noise_dn",
              {"expected a standard deviation in DN in [0, 64]", "got '65'"});
  ExpectError(world("gain_dn_per_e: 0.25", "gain_dn_per_e: -1"), "gain_dn_per_e: -1",
              "cameras[0].sensor.gain_dn_per_e",
              {"expected a gain in DN per electron in [0, 64]", "got '-1'"});
  ExpectError(world("gain_dn_per_e: 0.25", "gain_dn_per_e: .inf"), "gain_dn_per_e: .inf",
              "cameras[0].sensor.gain_dn_per_e", {"expected a finite number"});
  ExpectError(
      world("blur_samples: 16", "blur_sample: 16"), "blur_sample: 16",
      "cameras[0].sensor.blur_sample",
      {"unknown key 'blur_sample'", "expected one of: exposure, exposure_ms, blur_samples"});
  ExpectError(world("seed: 18446744073709551615", "seed: -1"), "seed: -1", "cameras[0].sensor.seed",
              {"expected an integer in [0, 18446744073709551615]", "got '-1'"});
  ExpectError(world("seed: 18446744073709551615", "seed: 18446744073709551616"),
              "seed: 18446744073709551616", "cameras[0].sensor.seed",
              {"expected an integer in [0, 18446744073709551615]"});
  ExpectError(world("seed: 18446744073709551615", "seed: abc"), "seed: abc",
              "cameras[0].sensor.seed", {"expected an integer", "got 'abc'"});
  ExpectError(WithSensors("      [1, 2]\n", kEyeSensor), "[1, 2]", "cameras[0].sensor",
              {"expected a sensor {exposure | exposure_ms", "got a list of 2"});

  // Eye camera: robot.cameras.left.sensor.
  const auto eye = [&](const std::string& from, const std::string& to) {
    return WithSensors(kWorldSensor, Replace(kEyeSensor, from, to));
  };
  ExpectError(eye("exposure_ms: 8", "exposure_ms: -8"), "exposure_ms: -8",
              "robot.cameras.left.sensor.exposure_ms",
              {"expected an exposure in milliseconds in [0, 1000]", "got '-8'"});
  ExpectError(eye("exposure_ms: 8\n", "exposure_ms: 8\n        exposure: 0.008\n"),
              "exposure_ms: 8", "robot.cameras.left.sensor.exposure_ms", {"not both"});
  ExpectError(eye("read_noise_dn: 2", "read_noise_dn: .NaN"), "read_noise_dn: .NaN",
              "robot.cameras.left.sensor.read_noise_dn", {"expected a finite number"});
  ExpectError(eye("seed: 42", "seed: -42"), "seed: -42", "robot.cameras.left.sensor.seed",
              {"expected an integer in [0, 18446744073709551615]", "got '-42'"});
  ExpectError(eye("seed: 42", "seed: 42\n        noise: 1"), "noise: 1",
              "robot.cameras.left.sensor.noise", {"unknown key 'noise'"});
  ExpectError(eye("exposure_ms: 8", "exposure_ms: 8\n        blur_samples: 0"), "blur_samples: 0",
              "robot.cameras.left.sensor.blur_samples", {"expected an integer in [1, 64]"});
}

// Issue 45: an EMVA 1288 sensor under a camera's `sensor: emva:`, from a preset or figures.
const std::string kEmvaSensor = R"(      exposure_ms: 10
      seed: 3
      emva:
        quantum_efficiency: 0.6
        gain_dn_per_e: 0.3
        dark_noise_e: 2.5
        saturation_e: 12000
        dsnu_dn: 0.6
        prnu_percent: 0.8
        bit_depth: 12
        black_level_dn: 64
        photons_per_second: 2.0e6
)";
const std::string kEmvaEyeSensor = R"(        exposure_ms: 10
        emva: {preset: imx174, bit_depth: 14}
)";

TEST_F(SceneLoaderTest, EmvaSensorsAreReadFromFiguresAndPresets) {
  const Scene scene = Load(WithSensors(kEmvaSensor, kEmvaEyeSensor));
  const SensorSpec& rig = scene.FindCamera("rig")->sensor;
  ASSERT_TRUE(rig.HasEmva());
  EXPECT_FALSE(rig.HasNoise());
  EXPECT_EQ(rig.emva->quantum_efficiency, 0.6);
  EXPECT_EQ(rig.emva->gain_dn_per_e, 0.3);
  EXPECT_EQ(rig.emva->dark_noise_e, 2.5);
  EXPECT_EQ(rig.emva->saturation_e, 12000.0);
  EXPECT_NEAR(rig.emva->dsnu_e, 2.0, kParseTolerance);  // 0.6 DN / 0.3 DN/e-
  EXPECT_EQ(rig.emva->prnu_percent, 0.8);
  EXPECT_EQ(rig.emva->bit_depth, 12);
  EXPECT_EQ(rig.emva->black_level_dn, 64.0);
  EXPECT_EQ(rig.emva->photons_per_second, 2.0e6);
  const SensorSpec& left = scene.FindCamera("left")->sensor;
  ASSERT_TRUE(left.HasEmva());
  const EmvaSensor imx174 = *FindEmvaPreset("imx174");
  EXPECT_EQ(left.emva->preset, "imx174");
  EXPECT_EQ(left.emva->saturation_e, imx174.saturation_e);
  EXPECT_EQ(left.emva->dark_noise_e, imx174.dark_noise_e);
  EXPECT_EQ(left.emva->bit_depth, 14);  // the key replaces the preset's 12
  EXPECT_FALSE(scene.FindCamera("right")->sensor.HasEmva());
}

// Issue 45: a sensor's colour and a camera's lens (camera_optics.h), on world and eye cameras.
std::string WithOptics(const std::string& world, const std::string& eye) {
  std::string text = Replace(kValid, "    clip: {near: 0.1, far: 20}\n",
                             "    clip: {near: 0.1, far: 20}\n" + world);
  return Replace(text, "  visible: false\n", "  visible: false\n  cameras:\n    left:\n" + eye);
}
const std::string kWorldOptics = R"(    sensor:
      color:
        cfa: grbg
        demosaic: edge_aware
        white_balance: {red: 1.5, blue: 2}
        tone_curve: {gamma: 1.8}
    lens:
      vignetting: {polynomial: [-0.3, 0.05, 0]}
      f_number: 2.8
      focal_length_mm: 6
      focus_distance: 1.5
      pixel_pitch_um: 3.45
      max_coc_px: 16
)";
const std::string kEyeOptics = R"(      sensor:
        color: {cfa: rggb, tone_curve: srgb}
      lens: {vignetting: cos4}
)";

TEST_F(SceneLoaderTest, ColorAndLensAreReadForWorldAndEyeCameras) {
  const Scene scene = Load(WithOptics(kWorldOptics, kEyeOptics));
  const CameraSpec& rig = *scene.FindCamera("rig");
  EXPECT_EQ(rig.sensor.color.cfa, CfaPattern::kGrbg);
  EXPECT_EQ(rig.sensor.color.demosaic, DemosaicMethod::kEdgeAware);
  EXPECT_EQ(rig.sensor.color.white_balance, (std::array<double, 3>{1.5, 1.0, 2.0}));
  EXPECT_EQ(rig.sensor.color.tone_curve, ToneCurveKind::kGamma);
  EXPECT_EQ(rig.sensor.color.gamma, 1.8);
  EXPECT_EQ(rig.lens.vignetting, VignettingModel::kPolynomial);
  EXPECT_EQ(rig.lens.vignetting_coefficients, (std::array<double, 3>{-0.3, 0.05, 0.0}));
  EXPECT_TRUE(rig.lens.HasDepthOfField());
  EXPECT_EQ(rig.lens.f_number, 2.8);
  EXPECT_NEAR(rig.lens.focal_length_m, 0.006, kParseTolerance);
  EXPECT_EQ(rig.lens.focus_distance_m, 1.5);
  EXPECT_NEAR(rig.lens.pixel_pitch_m, 3.45e-6, kParseTolerance);
  EXPECT_EQ(rig.lens.max_coc_px, 16.0);
  const CameraSpec& left = *scene.FindCamera("left");
  EXPECT_EQ(left.sensor.color.cfa, CfaPattern::kRggb);
  EXPECT_EQ(left.sensor.color.tone_curve, ToneCurveKind::kSrgb);
  EXPECT_EQ(left.lens.vignetting, VignettingModel::kCos4);
  EXPECT_FALSE(left.lens.HasDepthOfField());
  // Cameras without the keys: everything off.
  for (const char* name : {"right", "top"}) {
    EXPECT_FALSE(scene.FindCamera(name)->sensor.color.Enabled()) << name;
    EXPECT_FALSE(scene.FindCamera(name)->lens.Enabled()) << name;
  }
}

TEST_F(SceneLoaderTest, BadColorAndLensNameTheFileLineAndKey) {
  const auto world = [&](const std::string& from, const std::string& to) {
    return WithOptics(Replace(kWorldOptics, from, to), kEyeOptics);
  };
  ExpectError(world("cfa: grbg", "cfa: rgbg"), "cfa: rgbg", "cameras[0].sensor.color.cfa",
              {"expected a colour filter pattern (none, rggb, bggr, grbg, gbrg)", "got 'rgbg'"});
  ExpectError(world("demosaic: edge_aware", "demosaic: vng"), "demosaic: vng",
              "cameras[0].sensor.color.demosaic",
              {"expected a demosaicing method (bilinear, edge_aware)"});
  ExpectError(world("red: 1.5", "red: -1.5"), "red: -1.5",
              "cameras[0].sensor.color.white_balance.red",
              {"expected a gain in (0, 16]", "got '-1.5'"});
  ExpectError(world("{gamma: 1.8}", "{gamma: 0}"), "{gamma: 0}",
              "cameras[0].sensor.color.tone_curve.gamma", {"expected a display gamma in (0, 10]"});
  ExpectError(world("{gamma: 1.8}", "log"), "tone_curve: log", "cameras[0].sensor.color.tone_curve",
              {"expected a tone curve (or {gamma: 2.2}) (linear, gamma, srgb)", "got 'log'"});
  ExpectError(world("f_number: 2.8", "f_number: 0"), "f_number: 0", "cameras[0].lens.f_number",
              {"expected an f-number in (0, 1000]", "got '0'"});
  ExpectError(world("focus_distance: 1.5", "focus_distance: 0.004"), "focus_distance: 0.004",
              "cameras[0].lens.focus_distance",
              {"expected a focus distance in metres beyond the focal length (0.006 m)"});
  ExpectError(world("      focal_length_mm: 6\n", ""), "f_number: 2.8", "cameras[0].lens.f_number",
              {"depth of field needs the lens's 'focal_length_mm'"});
  ExpectError(world("      f_number: 2.8\n", ""), "focal_length_mm: 6",
              "cameras[0].lens.focal_length_mm", {"depth of field needs the lens's 'f_number'"});
  ExpectError(world("max_coc_px: 16", "max_coc_px: 0.5"), "max_coc_px: 0.5",
              "cameras[0].lens.max_coc_px",
              {"expected a largest circle of confusion in pixels in [1, 256]"});
  ExpectError(world("[-0.3, 0.05, 0]", "[-2, 0, 0]"), "[-2, 0, 0]",
              "cameras[0].lens.vignetting.polynomial",
              {"expected a relative illumination 1 + a1 r^2 + a2 r^4 + a3 r^6 >= 0"});
  ExpectError(world("f_number: 2.8", "aperture: 2.8"), "aperture: 2.8", "cameras[0].lens.aperture",
              {"unknown key 'aperture'"});
  ExpectError(WithOptics(kWorldOptics, Replace(kEyeOptics, "cos4", "cos3")), "cos3",
              "robot.cameras.left.lens.vignetting",
              {"expected a vignetting model (or {polynomial: [a1, a2, a3]}) (none, cos4)"});
}

TEST_F(SceneLoaderTest, BadEmvaSensorsNameTheFileLineAndKey) {
  const auto world = [&](const std::string& from, const std::string& to) {
    return WithSensors(Replace(kEmvaSensor, from, to), kEmvaEyeSensor);
  };
  const std::string key = "cameras[0].sensor.emva.";
  ExpectError(world("gain_dn_per_e: 0.3", "gain_dn_per_e: -0.3"), "gain_dn_per_e: -0.3",
              key + "gain_dn_per_e",
              {"expected a gain in DN per electron in (0, 64]", "got '-0.3'"});
  ExpectError(world("gain_dn_per_e: 0.3", "gain_dn_per_e: 0"), "gain_dn_per_e: 0",
              key + "gain_dn_per_e", {"in (0, 64]", "got '0'"});
  ExpectError(world("quantum_efficiency: 0.6", "quantum_efficiency: 1.2"),
              "quantum_efficiency: 1.2", key + "quantum_efficiency",
              {"expected a quantum efficiency in (0, 1]", "got '1.2'"});
  ExpectError(world("saturation_e: 12000", "saturation_e: 20"), "saturation_e: 20",
              key + "saturation_e",
              {"expected a saturation of at least 10 times the dark noise",
               "the saturation lies below the dark level's noise"});
  ExpectError(world("saturation_e: 12000", "saturation_e: -5"), "saturation_e: -5",
              key + "saturation_e", {"expected a saturation capacity in electrons in (0,"});
  ExpectError(world("black_level_dn: 64", "black_level_dn: 5000"), "black_level_dn: 5000",
              key + "black_level_dn",
              {"expected a black level below the largest 12-bit DN (4095), got 5000 DN"});
  ExpectError(world("bit_depth: 12", "bit_depth: 20"), "bit_depth: 20", key + "bit_depth",
              {"expected an integer in [8, 16]", "got '20'"});
  ExpectError(world("prnu_percent: 0.8", "prnu_percent: 30"), "prnu_percent: 30",
              key + "prnu_percent", {"expected a PRNU in percent in [0, 20]"});
  ExpectError(world("dsnu_dn: 0.6", "dsnu_dn: 0.6\n        dsnu_e: 2"), "dsnu_dn: 0.6",
              key + "dsnu_dn", {"give either 'dsnu_e' (electrons) or 'dsnu_dn', not both"});
  ExpectError(world("photons_per_second: 2.0e6", "photons_per_second: 0"), "photons_per_second: 0",
              key + "photons_per_second", {"expected photons per second in (0, 1000000000000]"});
  ExpectError(world("bit_depth: 12", "bit_depth: 12\n        full_well: 3"), "full_well: 3",
              key + "full_well",
              {"unknown key 'full_well'", "expected one of: preset, quantum_efficiency"});
  // The emva block against the rest of the sensor.
  ExpectError(world("seed: 3\n", "seed: 3\n      read_noise_dn: 1\n"), "read_noise_dn: 1",
              "cameras[0].sensor.read_noise_dn",
              {"give either the noise figures (read_noise_dn, gain_dn_per_e) or an emva sensor"});
  // A block map's line is its first key's.
  ExpectError(world("      exposure_ms: 10\n", ""), "quantum_efficiency: 0.6",
              "cameras[0].sensor.emva", {"an emva sensor needs an exposure > 0"});
  // A preset by an unknown name, on the eye camera.
  ExpectError(WithSensors(kEmvaSensor, Replace(kEmvaEyeSensor, "imx174", "imx999")), "imx999",
              "robot.cameras.left.sensor.emva.preset",
              {"unknown sensor preset 'imx999'", "the presets are: imx174, imx264"});
}

}  // namespace
}  // namespace saccade::scene

namespace saccade::scene {
namespace {

// Issue 18: a camera of 200000 x 200000 pixels aborted the process (std::bad_alloc) when the
// renderer allocated for it. Sizes are checked when the scene loads, with the key named.
class SceneLimitsTest : public ::testing::Test {
 protected:
  static FileError Error(const std::string& text) {
    try {
      Scene::FromYamlString(text, "limits.yaml", std::filesystem::temp_directory_path());
    } catch (const FileError& error) {
      return error;
    }
    ADD_FAILURE() << "no FileError for:\n" << text;
    return FileError("", 0, "", "");
  }
  static std::string Camera(const std::string& name, int width, int height) {
    return "  - name: " + name + "\n    calibration: {width: " + std::to_string(width) +
           ", height: " + std::to_string(height) +
           ", fx: 1000, fy: 1000}\n    look_at: {eye: [0, 0, 1], target: [1, 0, 1]}\n";
  }
};

TEST_F(SceneLimitsTest, AHugeCameraIsRefusedAtItsCalibrationBeforeRendering) {
  const FileError side = Error("cameras:\n" + Camera("huge", 200000, 200000));
  EXPECT_EQ(side.line(), 3) << side.what();
  EXPECT_EQ(side.key(), "cameras[0].calibration") << side.what();
  EXPECT_THAT(side.what(),
              ::testing::HasSubstr("camera 'huge' is 200000x200000 px: a side above 16384 px"));
  // Within the side but beyond the pixels of one camera.
  const FileError pixels = Error("cameras:\n" + Camera("wide", 16384, 8192));
  EXPECT_THAT(pixels.what(),
              ::testing::HasSubstr("16384x8192 px = 134.2 Mpx, more than the 67 Mpx"));
  // The largest camera allowed loads.
  EXPECT_NO_THROW(Scene::FromYamlString("cameras:\n" + Camera("big", 8192, 8192), "ok.yaml",
                                        std::filesystem::temp_directory_path()));
}

TEST_F(SceneLimitsTest, CamerasTogetherAndTheirNumberAreBounded) {
  std::string five = "cameras:\n";
  for (int i = 0; i < 5; ++i) five += Camera("c" + std::to_string(i), 8192, 8192);
  const FileError total = Error(five);
  EXPECT_THAT(total.what(), ::testing::HasSubstr("the cameras have 335.5 Mpx together"));
  std::string many = "cameras:\n";
  for (int i = 0; i < kMaxCameras + 1; ++i) many += Camera("c" + std::to_string(i), 64, 48);
  const FileError count = Error(many);
  EXPECT_EQ(count.key(), "cameras") << count.what();
  EXPECT_THAT(count.what(), ::testing::HasSubstr("65 cameras, more than the 64"));
}

}  // namespace
}  // namespace saccade::scene
