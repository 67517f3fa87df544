// The shipped scenes, camera poses, the robot's body, and the Scene constructor's checks.

#include "saccade/scene/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"
#include "scene/scene_test_util.h"

namespace saccade::scene {
namespace {

using testing::kSourceDir;
using testing::Replace;
using testing::TempDir;

// Geometry in double from float models: float precision on metre-sized values.
constexpr double kFloatTolerance = 1e-6;
// Rotations built in double: a few ulps.
constexpr double kTolerance = 1e-12;

const Scene& Portraits() {
  static const Scene scene = Scene::Load(kSourceDir + "/scenes/astronaut_and_cat.yaml");
  return scene;
}
const Scene& Bench() {
  static const Scene scene = Scene::Load(kSourceDir + "/scenes/bench.yaml");
  return scene;
}

const Object& FindObject(const Scene& scene, const std::string& name) {
  for (const Object& object : scene.objects()) {
    if (object.name == name) return object;
  }
  ADD_FAILURE() << "no object " << name;
  return scene.objects().front();
}

// The 27 points of the 3 x 3 x 3 grid over a box (corners, edge and face centres, centre).
std::vector<Eigen::Vector3d> GridPoints(const Eigen::AlignedBox3f& box) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 27; ++i) {
    const Eigen::Vector3f t(0.5f * (i % 3), 0.5f * ((i / 3) % 3), 0.5f * (i / 9));
    points.push_back((box.min() + t.cwiseProduct(box.sizes())).cast<double>());
  }
  return points;
}

// Where a point of the world lands in a camera: the pixel when it is in front of the near
// plane and inside the image.
std::optional<Eigen::Vector2d> SeenAt(const Scene& scene, const CameraSpec& camera,
                                      const SceneState& state, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d p_C = scene.CameraPose(camera, state).inverse() * p_W;
  if (p_C.z() <= camera.clip.near) return std::nullopt;
  const auto uv = camera.model.Project(p_C);
  if (!uv || !camera.model.Contains(*uv)) return std::nullopt;
  return uv;
}

TEST(ShippedScenes, PortraitsLoad) {
  const Scene& scene = Portraits();
  EXPECT_EQ(scene.objects().size(), 8u);
  EXPECT_EQ(scene.lights().size(), 3u);
  ASSERT_EQ(scene.cameras().size(), 3u);
  EXPECT_NE(scene.FindCamera("left"), nullptr);
  EXPECT_NE(scene.FindCamera("right"), nullptr);
  EXPECT_NE(scene.FindCamera("overview"), nullptr);
  ASSERT_TRUE(scene.robot().has_value());
  EXPECT_EQ(scene.robot()->head.name(), "popeye");
  EXPECT_EQ(scene.robot()->id, 9u);
  EXPECT_TRUE(scene.ground().enabled);
  // Every distinct model once.
  for (std::size_t i = 0; i < scene.models().size(); ++i) {
    for (std::size_t j = i + 1; j < scene.models().size(); ++j) {
      EXPECT_NE(scene.models()[i], scene.models()[j]);
    }
  }
  // Pictures take their aspect from the image: the astronaut is 512 x 512, the cat 451 x 300.
  const Model& astronaut = *FindObject(scene, "astronaut").model;
  EXPECT_NEAR(astronaut.bounds.sizes().y(), 0.8, kFloatTolerance);
  EXPECT_NEAR(astronaut.bounds.sizes().z(), 0.8, kFloatTolerance);
  EXPECT_EQ(astronaut.bounds.sizes().x(), 0.0f);
  const Model& chelsea = *FindObject(scene, "chelsea").model;
  EXPECT_NEAR(chelsea.bounds.sizes().y() / chelsea.bounds.sizes().z(), 451.0 / 300.0,
              kFloatTolerance);
  ASSERT_NE(chelsea.materials[0].texture, nullptr);
  EXPECT_EQ(chelsea.materials[0].texture->image.width(), 451);
}

TEST(ShippedScenes, AstronautsFaceIsFaceDetectorSizedInTheEyeCamerasAtRest) {
  const Scene& scene = Portraits();
  const Object& astronaut = FindObject(scene, "astronaut");
  const SceneState state = scene.InitialState();
  const geometry::Pose X_WO = scene.ObjectPose(astronaut, state);
  const Eigen::AlignedBox3f& b = astronaut.model->bounds;
  // The face in astronaut.png spans about x 165..285, y 60..190 of 512 x 512 pixels.
  const auto on_picture = [&](double u, double v) {
    const double y = b.min().y() + u / 512.0 * b.sizes().y();
    const double z = b.max().z() - v / 512.0 * b.sizes().z();
    return Eigen::Vector3d(X_WO * Eigen::Vector3d(0.0, y, z));
  };
  for (const char* name : {"left", "right"}) {
    const CameraSpec& camera = *scene.FindCamera(name);
    const auto left = SeenAt(scene, camera, state, on_picture(165, 125));
    const auto right = SeenAt(scene, camera, state, on_picture(285, 125));
    const auto top = SeenAt(scene, camera, state, on_picture(225, 60));
    const auto bottom = SeenAt(scene, camera, state, on_picture(225, 190));
    ASSERT_TRUE(left && right && top && bottom) << name << ": the face is not in view";
    const double width = (*right - *left).norm();
    EXPECT_GT(width, 80.0) << name;
    EXPECT_LT(width, 150.0) << name;
    // Not mirrored: the image's right is the camera's right; its top is up.
    EXPECT_GT(right->x(), left->x()) << name;
    EXPECT_LT(top->y(), bottom->y()) << name;
  }
}

TEST(ShippedScenes, BenchLoadsAndSharesTheMugModel) {
  const Scene& scene = Bench();
  EXPECT_EQ(scene.objects().size(), 13u);
  EXPECT_EQ(scene.lights().size(), 1u);
  ASSERT_EQ(scene.cameras().size(), 2u);
  for (const CameraSpec& camera : scene.cameras()) {
    EXPECT_EQ(camera.model.intrinsics().width(), 1024);
    EXPECT_EQ(camera.model.intrinsics().height(), 768);
    // What `saccade bench` times the effects with: a lens, noise and an exposure.
    EXPECT_EQ(camera.model.distortion().model(), geometry::DistortionModel::kRadialTangential);
    EXPECT_FALSE(camera.model.distortion().IsIdentity());
    EXPECT_TRUE(camera.sensor.HasNoise()) << camera.name;
    EXPECT_TRUE(camera.sensor.HasBlur()) << camera.name;
  }
  // The eye cameras' calibrations replace the description's, with its intrinsics.
  const auto popeye = head::HeadDescription::FromYamlFile(testing::kPopeye);  // its own file
  EXPECT_EQ(scene.cameras()[0].model.intrinsics(), popeye.left_camera().intrinsics());
  EXPECT_EQ(scene.cameras()[1].model.intrinsics(), popeye.right_camera().intrinsics());
  EXPECT_EQ(scene.ground().pattern, Ground::Pattern::kChecker);
  EXPECT_EQ(scene.ground().size, 10.0);
  std::shared_ptr<const Model> mug;
  int mugs = 0, pictures = 0;
  for (const Object& object : scene.objects()) {
    if (object.name.rfind("mug", 0) == 0) {
      if (mug == nullptr) mug = object.model;
      EXPECT_EQ(object.model, mug) << object.name;  // the same shared_ptr
      ++mugs;
    }
    if (object.model->source.rfind("picture:", 0) == 0) {
      EXPECT_NEAR(object.model->bounds.sizes().z(), 0.4, kFloatTolerance);
      ++pictures;
    }
  }
  EXPECT_EQ(mugs, 8);
  EXPECT_EQ(pictures, 4);
  EXPECT_EQ(std::count(scene.models().begin(), scene.models().end(), mug), 1);
}

TEST(ShippedScenes, BenchPortraitsAndMugsAreInViewOfBothEyesAtRest) {
  const Scene& scene = Bench();
  const SceneState state = scene.InitialState();
  EXPECT_EQ(state.joints, head::JointState::Popeye(0, 0, 0, 0));
  for (const CameraSpec& camera : scene.cameras()) {
    for (const Object& object : scene.objects()) {
      const geometry::Pose X_WO = scene.ObjectPose(object, state);
      if (object.name == "table") {
        // Its top face's centre.
        const Eigen::Vector3d top = X_WO * Eigen::Vector3d(0, 0, 0.5 * object.scale.z());
        EXPECT_TRUE(SeenAt(scene, camera, state, top)) << camera.name << " table";
        continue;
      }
      for (const Eigen::Vector3d& p : GridPoints(object.model->bounds)) {
        const Eigen::Vector3d p_W = X_WO * Eigen::Vector3d(p.cwiseProduct(object.scale));
        EXPECT_TRUE(SeenAt(scene, camera, state, p_W))
            << camera.name << " " << object.name << " " << p_W.transpose();
      }
    }
  }
}

TEST(CameraPose, EyeCamerasFollowForwardKinematics) {
  const Scene& scene = Portraits();
  const CameraSpec& left = *scene.FindCamera("left");
  const CameraSpec& right = *scene.FindCamera("right");
  EXPECT_EQ(left.mount, CameraMount::kLeftEye);
  EXPECT_EQ(right.mount, CameraMount::kRightEye);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-0.7, 0.7);
  for (int i = 0; i < 20; ++i) {
    SceneState state;
    state.time = i;
    state.joints = head::JointState::Popeye(angle(rng), angle(rng), angle(rng), angle(rng));
    const head::PopeyeJoints q{state.joints[0], state.joints[1], state.joints[2], state.joints[3]};
    const head::HeadFrames frames =
        head::ForwardKinematics(*scene.robot()->head.AppendixAHead(), q);
    EXPECT_TRUE(scene.CameraPose(left, state).isApprox(frames.X_WCamLeft, kTolerance));
    EXPECT_TRUE(scene.CameraPose(right, state).isApprox(frames.X_WCamRight, kTolerance));
  }
  // At rest POPEYE's eyes are 1.2 m up, 0.1 m to each side, looking along +x.
  const geometry::Pose X_WL = scene.CameraPose(left, scene.InitialState());
  EXPECT_TRUE(X_WL.translation().isApprox(Eigen::Vector3d(0, 0.1, 1.2), kTolerance));
  EXPECT_TRUE((X_WL.linear().col(2)).isApprox(Eigen::Vector3d::UnitX(), kTolerance));
}

TEST(CameraPose, LookAtPointsTheOpticalAxisAtTheTarget) {
  const Scene& scene = Portraits();
  const CameraSpec& overview = *scene.FindCamera("overview");
  EXPECT_EQ(overview.mount, CameraMount::kWorld);
  const geometry::Pose X_WC = scene.CameraPose(overview, scene.InitialState());
  const Eigen::Vector3d eye(-1.0, -2.4, 2.1), target(2.0, 0.0, 0.9);
  EXPECT_TRUE(X_WC.translation().isApprox(eye, kTolerance));
  const Eigen::Matrix3d R = X_WC.linear();
  EXPECT_TRUE(R.col(2).isApprox((target - eye).normalized(), kTolerance));  // z forward
  EXPECT_NEAR(R.col(0).z(), 0.0, kTolerance);                               // x right, level
  EXPECT_LT(R.col(1).z(), 0.0);                                             // y down
  EXPECT_NEAR(R.determinant(), 1.0, kTolerance);
  EXPECT_TRUE((R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), kTolerance));
  // The target projects onto the principal point.
  const auto uv = overview.model.Project(X_WC.inverse() * target);
  ASSERT_TRUE(uv);
  EXPECT_NEAR(uv->x(), overview.model.intrinsics().cx(), 1e-9);
  EXPECT_NEAR(uv->y(), overview.model.intrinsics().cy(), 1e-9);
  // With the target to the camera's right, u grows.
  const Eigen::Vector3d to_the_right = target + 0.5 * R.col(0);
  EXPECT_GT(overview.model.Project(X_WC.inverse() * to_the_right)->x(),
            overview.model.intrinsics().cx());
}

// The pose of a robot part's link in the world.
geometry::Pose LinkPose(const head::HeadModel& head, const head::JointState& q, int link) {
  std::vector<geometry::Pose> X_WL;
  head.ForwardKinematics(q.empty() ? head.HomePosture() : q.values(), &X_WL);
  return X_WL[link];
}

TEST(RobotBody, EyesCannotSeeTheirOwnEyeNorTheHeadAnywhereWithinTheLimits) {
  const Scene& scene = Portraits();
  const Robot& robot = *scene.robot();
  ASSERT_GE(robot.parts.size(), 5u);
  std::mt19937 rng(11);
  const auto uniform = [&rng](const head::JointLimits& l) {
    return std::uniform_real_distribution<double>(l.min, l.max)(rng);
  };
  for (int trial = 0; trial < 200; ++trial) {
    head::JointState q = head::JointState::Popeye(0, 0, 0, 0);
    for (int joint = 0; joint < 4; ++joint) q[joint] = uniform(robot.head.joint(joint).limits);
    if (trial == 0) q = head::JointState::Popeye(0, 0, 0, 0);
    SceneState state{0.0, q, {}, {}};
    const int left_eye = robot.head.tree().FindLink("left_eye_link");
    const int right_eye = robot.head.tree().FindLink("right_eye_link");
    for (const RobotPart& part : robot.parts) {
      const geometry::Pose X_WPart = LinkPose(robot.head, q, part.link) * part.X_LinkPart;
      for (const Eigen::Vector3d& p : GridPoints(part.model->bounds)) {
        const Eigen::Vector3d p_W = X_WPart * Eigen::Vector3d(p.cwiseProduct(part.scale));
        for (const char* name : {"left", "right"}) {
          const CameraSpec& camera = *scene.FindCamera(name);
          const bool own_eye = (part.link == left_eye && camera.mount == CameraMount::kLeftEye) ||
                               (part.link == right_eye && camera.mount == CameraMount::kRightEye);
          const Eigen::Vector3d p_C = scene.CameraPose(camera, state).inverse() * p_W;
          // Its own eye lies behind its optical centre: never in the view, whatever the near
          // plane.
          if (own_eye) {
            EXPECT_LT(p_C.z(), 0.0) << name << " trial " << trial;
          }
          EXPECT_FALSE(SeenAt(scene, camera, state, p_W))
              << name << " sees part of the robot (link " << static_cast<int>(part.link)
              << ") at joints " << q[0] << " " << q[1] << " " << q[2] << " " << q[3];
        }
      }
    }
  }
}

TEST(RobotBody, IsSizedFromTheHalfBaseline) {
  TempDir dir;
  std::ifstream in(testing::kPopeye);
  const std::string popeye((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  dir.Write("wide.yaml", Replace(popeye, "half_baseline: 0.1", "half_baseline: 0.2"));
  dir.Write("popeye.yaml", popeye);
  const Scene narrow = Scene::FromYamlString("robot: {head: popeye.yaml}", "a.yaml", dir.path());
  const Scene wide = Scene::FromYamlString("robot: {head: wide.yaml}", "b.yaml", dir.path());
  ASSERT_EQ(narrow.robot()->parts.size(), wide.robot()->parts.size());
  for (std::size_t i = 0; i < narrow.robot()->parts.size(); ++i) {
    EXPECT_TRUE(wide.robot()->parts[i].scale.isApprox(2.0 * narrow.robot()->parts[i].scale));
  }
  // The robot's parts are in models(), once each.
  EXPECT_FALSE(narrow.models().empty());
  for (const RobotPart& part : narrow.robot()->parts) {
    EXPECT_EQ(std::count(narrow.models().begin(), narrow.models().end(), part.model), 1);
  }
}

// --- The constructor (scenes built in code) ------------------------------------------------

class SceneConstructorTest : public ::testing::Test {
 protected:
  SceneConstructorTest() : head_(head::HeadModel::FromFile(testing::kPopeye)) {
    objects_.push_back(Object{"a", 1, MakeBox({1, 0, 0, 1}), {1, 1, 1}, Motion()});
    objects_.push_back(Object{"b", 2, MakeSphere({0, 1, 0, 1}), {1, 1, 1}, Motion()});
    cameras_.push_back(CameraSpec{"rig",
                                  head_.camera(0).model,
                                  CameraMount::kWorld,
                                  geometry::Pose::Identity(),
                                  {0.05, 50.0},
                                  SensorSpec{}});
  }
  Scene Make() const {
    return Scene({0.5f, 0.5f, 0.5f}, lights_, ground_, objects_, cameras_, robot_);
  }

  head::HeadModel head_;
  std::vector<Light> lights_{Light{}};
  Ground ground_;
  std::vector<Object> objects_;
  std::vector<CameraSpec> cameras_;
  std::optional<Robot> robot_;
};

TEST_F(SceneConstructorTest, ValidSceneBuilds) {
  const Scene scene = Make();
  EXPECT_EQ(scene.models().size(), 2u);
  EXPECT_TRUE(scene.InitialState().joints.empty());  // no robot, no joints
  EXPECT_TRUE(
      scene.CameraPose(cameras_[0], scene.InitialState()).isApprox(geometry::Pose::Identity()));
}

TEST_F(SceneConstructorTest, RejectsDuplicateNamesAndIds) {
  objects_[1].name = "a";
  EXPECT_THROW(Make(), InvalidArgument);
  objects_[1].name = "b";
  objects_[1].id = 1;
  EXPECT_THROW(Make(), InvalidArgument);
  objects_[1].id = 0;
  EXPECT_THROW(Make(), InvalidArgument);
  objects_[1].id = 2;
  cameras_.push_back(cameras_[0]);
  EXPECT_THROW(Make(), InvalidArgument);
}

TEST_F(SceneConstructorTest, RejectsBadObjects) {
  objects_[0].model = nullptr;
  EXPECT_THROW(Make(), InvalidArgument);
  objects_[0].model = MakeBox({1, 0, 0, 1});
  objects_[0].scale = {1, 0, 1};
  EXPECT_THROW(Make(), InvalidArgument);
  objects_[0].scale = {1, std::numeric_limits<double>::quiet_NaN(), 1};
  EXPECT_THROW(Make(), InvalidArgument);
  objects_[0].scale = {1, 1, 1};
  // A model whose index is out of range.
  Model broken = *MakeBox({1, 0, 0, 1});
  broken.meshes[0].indices[5] = 1000;
  objects_[0].model = std::make_shared<const Model>(broken);
  try {
    Make();
    ADD_FAILURE() << "accepted an index out of range";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("out of range"), std::string::npos) << error.what();
  }
  // Non-unit normals.
  broken = *MakeBox({1, 0, 0, 1});
  broken.meshes[0].normals[0] *= 2.0f;
  objects_[0].model = std::make_shared<const Model>(broken);
  EXPECT_THROW(Make(), InvalidArgument);
}

TEST_F(SceneConstructorTest, RejectsBadLightsGroundAndBackground) {
  lights_[0].intensity = -1.0f;
  EXPECT_THROW(Make(), InvalidArgument);
  lights_[0] = Light{};
  lights_[0].direction_W = Eigen::Vector3d::Zero();
  EXPECT_THROW(Make(), InvalidArgument);
  lights_[0] = Light{};
  ground_.cell = 0.0;
  EXPECT_THROW(Make(), InvalidArgument);
  ground_ = Ground{};
  EXPECT_THROW(Scene({2.0f, 0.0f, 0.0f}, lights_, ground_, objects_, cameras_, robot_),
               InvalidArgument);
}

TEST_F(SceneConstructorTest, RejectsBadCameras) {
  cameras_[0].clip = {1.0, 0.5};
  EXPECT_THROW(Make(), InvalidArgument);
  cameras_[0].clip = {0.05, 50.0};
  cameras_[0].X_WC.linear() *= 2.0;
  EXPECT_THROW(Make(), InvalidArgument);
  cameras_[0].X_WC = geometry::Pose::Identity();
  cameras_[0].mount = CameraMount::kLeftEye;  // no robot
  EXPECT_THROW(Make(), InvalidArgument);
  robot_.emplace(Robot{head_, head_.Home(), true, {}, 3});
  EXPECT_NO_THROW(Make());
  robot_->id = 2;  // an object's
  EXPECT_THROW(Make(), InvalidArgument);
  robot_->id = 3;
  robot_->initial_joints[0] = 10.0;  // beyond its limits
  EXPECT_THROW(Make(), InvalidArgument);
}

}  // namespace
}  // namespace saccade::scene
