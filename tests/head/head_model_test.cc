#include "saccade/head/head_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"

namespace saccade::head {
namespace {

namespace fs = std::filesystem;
using geometry::Pose;
using ::testing::AllOf;
using ::testing::HasSubstr;

// The tree and appendix A's chain multiply the same rotations in a different grouping (and
// the paper's axes through a permutation): rounding of a few ulps of the ~1 m poses.
constexpr double kMatrixTolerance = 1e-14;
constexpr int kConfigurations = 1000;

const fs::path kSource = SACCADE_SOURCE_DIR;

double PoseDifference(const Pose& a, const Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

Eigen::VectorXd RandomPosture(const HeadModel& head, std::mt19937_64* random) {
  Eigen::VectorXd q(head.num_joints());
  for (int i = 0; i < q.size(); ++i) {
    const JointLimits& l = head.joint(i).limits;
    q[i] = std::uniform_real_distribution<double>(l.min, l.max)(*random);
  }
  return q;
}

// POPEYE's cameras and eye centres through a head model, against appendix A's chain (eqs. 4-8)
// on the legacy description.
double WorstAgainstAppendixA(const HeadModel& head, const HeadDescription& legacy) {
  std::mt19937_64 random(7);
  std::vector<Pose> X_WL;
  double worst = 0.0;
  for (int n = 0; n < kConfigurations; ++n) {
    const Eigen::VectorXd q = RandomPosture(head, &random);
    head.ForwardKinematics(q, &X_WL);
    const HeadFrames f = ForwardKinematics(legacy, PopeyeJoints{q[0], q[1], q[2], q[3]});
    worst = std::max(worst, PoseDifference(head.CameraPose(0, X_WL), f.X_WCamLeft));
    worst = std::max(worst, PoseDifference(head.CameraPose(1, X_WL), f.X_WCamRight));
    const int left_eye = head.tree().FindLink("left_eye_link");
    worst = std::max(worst, (X_WL[left_eye].translation() - f.X_WL.translation()).norm());
  }
  return worst;
}

TEST(HeadModel, PopeyesLegacyFileIsATreeWithAppendixAsForwardKinematics) {
  const HeadDescription legacy = HeadDescription::FromYamlFile(kSource / "robots/popeye.yaml");
  const HeadModel head = HeadModel::FromFile(kSource / "robots/popeye.yaml");
  ASSERT_EQ(head.num_joints(), 4);
  for (const Joint j : kAllJoints) {
    EXPECT_EQ(head.joint_name(static_cast<int>(j)), JointName(j));
    EXPECT_EQ(head.joint(static_cast<int>(j)).limits.max, legacy.limits(j).max);
    EXPECT_EQ(head.joint(static_cast<int>(j)).servo->id, legacy.servo(j)->id);
  }
  ASSERT_TRUE(head.appendix_a().has_value());
  ASSERT_EQ(head.fixation_rule().symmetric.size(), 1u);
  EXPECT_EQ(head.camera(0).model.intrinsics().fx(), legacy.left_camera().intrinsics().fx());
  EXPECT_LE(WorstAgainstAppendixA(head, legacy), kMatrixTolerance);
}

TEST(HeadModel, PopeyesUrdfIsAppendixAsChainToo) {
  const HeadDescription legacy = HeadDescription::FromYamlFile(kSource / "robots/popeye.yaml");
  const HeadModel head = HeadModel::FromFile(kSource / "robots/popeye_urdf.yaml");
  ASSERT_EQ(head.num_joints(), 4);
  for (const Joint j : kAllJoints) EXPECT_EQ(head.joint_name(static_cast<int>(j)), JointName(j));
  EXPECT_FALSE(head.appendix_a().has_value());
  EXPECT_FALSE(head.visuals().empty());
  EXPECT_LE(WorstAgainstAppendixA(head, legacy), kMatrixTolerance);
}

TEST(HeadModel, EveryShippedHeadFileLoadsWithItsMeshes) {
  int heads = 0;
  for (const auto& entry : fs::directory_iterator(kSource / "robots")) {
    if (entry.path().extension() != ".yaml") continue;
    const HeadModel head = HeadModel::FromFile(entry.path());
    ++heads;
    for (const UrdfVisual& visual : head.visuals()) {
      if (visual.shape == UrdfVisual::Shape::kMesh) {
        EXPECT_TRUE(fs::is_regular_file(visual.mesh_path)) << visual.mesh_uri;
      }
    }
    // At home the cameras look along the world's +x (every shipped head faces the scenes).
    std::vector<Pose> X_WL;
    head.ForwardKinematics(head.HomePosture(), &X_WL);
    for (int eye = 0; eye < 2; ++eye) {
      EXPECT_GT(head.CameraPose(eye, X_WL).linear().col(2).x(), 0.99) << entry.path();
    }
  }
  EXPECT_GE(heads, 5);
}

TEST(HeadModel, OffsetsOfTheGeneralAppendixAChainAreKept) {
  // D, H and the deltas move the frames (appendix A's extension): the tree follows them.
  HeadDescription base = HeadDescription::FromYamlFile(kSource / "robots/popeye.yaml");
  HeadGeometry g = base.geometry();
  g.D = 0.03;
  g.H = 0.05;
  g.delta_l = 0.012;
  g.delta_r = 0.008;
  std::array<JointLimits, 4> limits;
  std::array<std::optional<ServoMapping>, 4> servos;
  for (const Joint j : kAllJoints) limits[static_cast<int>(j)] = base.limits(j);
  const HeadDescription legacy(base.name(), g, limits, base.X_WB(), base.left_camera(),
                               base.right_camera(), servos);
  EXPECT_LE(WorstAgainstAppendixA(HeadModel::FromDescription(legacy), legacy), kMatrixTolerance);
}

// A scratch folder with a URDF and the head files the tests write beside it.
class HeadFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() / ("saccade-head-model-" + std::to_string(getpid()));
    fs::remove_all(folder_);
    fs::create_directories(folder_);
    std::ofstream(folder_ / "head.urdf") << R"(<?xml version="1.0"?>
<robot name="two_eyes">
  <link name="base"/><link name="neck"/><link name="left_eye"/><link name="right_eye"/>
  <link name="left_optical"/>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="neck"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="2"/></joint>
  <joint name="roll" type="revolute"><parent link="neck"/><child link="left_eye"/>
    <origin xyz="0.05 0.03 0.1"/><axis xyz="1 0 0"/><limit lower="-0.5" upper="0.5" effort="1" velocity="2"/></joint>
  <joint name="vergence" type="revolute"><parent link="neck"/><child link="right_eye"/>
    <origin xyz="0.05 -0.03 0.1"/><axis xyz="0 0 1"/><limit lower="-0.6" upper="0.6" effort="1" velocity="6"/>
    <mimic joint="yaw" multiplier="-2"/></joint>
  <joint name="left_mount" type="fixed"><parent link="left_eye"/><child link="left_optical"/>
    <origin rpy="-1.5707963267948966 0 -1.5707963267948966"/></joint>
  <gazebo reference="right_eye"><sensor type="camera" name="right_camera"><camera>
    <horizontal_fov>0.8</horizontal_fov><image><width>320</width><height>240</height></image>
  </camera></sensor></gazebo>
</robot>
)";
  }
  void TearDown() override { fs::remove_all(folder_); }

  HeadModel Load(const std::string& body) {
    std::ofstream(folder_ / "head.yaml") << "urdf: head.urdf\n" << body;
    return HeadModel::FromFile(folder_ / "head.yaml");
  }
  std::string ErrorOf(const std::string& body) {
    try {
      Load(body);
    } catch (const FileError& e) {
      return e.what();
    }
    return "no error";
  }

  fs::path folder_;
};

const std::string kCameras = R"(cameras:
  left: {link: left_optical, width: 640, height: 480, fx: 500, fy: 500}
  right: {gazebo_sensor: right_camera}
)";
const std::string kJoints = R"(joints:
  yaw: {max_acceleration_deg: 500, servo: {id: 1}}
  roll: {driven: false, hold_deg: 5}
)";

TEST_F(HeadFileTest, AHeadFileAddsCamerasDrivenJointsAndTheRuleToItsUrdf) {
  const HeadModel head = Load(kCameras + kJoints + R"(pose: {position: [0, 0, 1.2]}
fixation: {weights: {yaw: 3}}
)");
  EXPECT_EQ(head.name(), "two_eyes");  // the URDF's, without a name key
  ASSERT_EQ(head.num_joints(), 2);     // vergence mimics yaw
  const int yaw = head.FindJoint("yaw");
  const int roll = head.FindJoint("roll");
  // The mimic's range [-0.6, 0.6] at -2 * yaw narrows yaw's [-1, 1] to [-0.3, 0.3].
  EXPECT_DOUBLE_EQ(head.joint(yaw).limits.min, -0.3);
  EXPECT_DOUBLE_EQ(head.joint(yaw).limits.max, 0.3);
  EXPECT_EQ(head.joint(yaw).servo->id, 1);
  EXPECT_FALSE(head.joint(roll).driven);
  EXPECT_DOUBLE_EQ(head.HomePosture()[roll], 5 * M_PI / 180);
  EXPECT_TRUE(head.fixation_rule().hold[roll]);
  EXPECT_EQ(head.fixation_rule().weights[yaw], 3.0);
  EXPECT_EQ(head.camera(0).model.intrinsics().fx(), 500.0);
  EXPECT_EQ(head.camera(1).model.intrinsics().fx(), 160 / std::tan(0.4));
  EXPECT_EQ(head.X_WB().translation().z(), 1.2);
  EXPECT_FALSE(head.urdf_xml().empty());
}

TEST_F(HeadFileTest, BadHeadFilesNameTheKeyAndWhatWasExpected) {
  EXPECT_THAT(ErrorOf(kCameras + "joints:\n  pitch: {max_acceleration_deg: 5}\n"),
              AllOf(HasSubstr("head.yaml:"), HasSubstr("the URDF has no joint 'pitch'")));
  EXPECT_THAT(ErrorOf(kCameras + "joints:\n  vergence: {max_acceleration_deg: 5}\n"),
              HasSubstr("joint 'vergence' is a mimic"));
  EXPECT_THAT(ErrorOf(kCameras), AllOf(HasSubstr("joints.yaw"), HasSubstr("max_acceleration_deg")));
  EXPECT_THAT(
      ErrorOf(kCameras + "joints:\n  yaw: {max_acceleration_deg: 5, limits_deg: [-80, 10]}\n"
                         "  roll: {driven: false}\n"),
      HasSubstr("the head file may only narrow"));
  EXPECT_THAT(ErrorOf(R"(cameras:
  left: {link: left_lens, width: 640, height: 480, fx: 500, fy: 500}
  right: {gazebo_sensor: right_camera}
)" + kJoints),
              HasSubstr("the URDF has no link 'left_lens'"));
  EXPECT_THAT(ErrorOf(R"(cameras:
  left: {link: left_optical, width: 640, height: 480, fx: 500, fy: 500}
  right: {gazebo_sensor: right_cam}
)" + kJoints),
              HasSubstr("no camera sensor 'right_cam' (it has: right_camera)"));
  EXPECT_THAT(ErrorOf(kCameras + kJoints + "fixation: {hold: [neck]}\n"),
              HasSubstr("'neck' is not an actuated joint"));
  EXPECT_THAT(ErrorOf(kCameras + kJoints + "fixation: {weights: {yaw: 0}}\n"),
              AllOf(HasSubstr("fixation.weights.yaw"), HasSubstr("expected a positive number")));
  EXPECT_THAT(ErrorOf(kCameras + R"(joints:
  yaw: {max_acceleration_deg: 500, servo: {id: 1}}
  roll: {max_acceleration_deg: 500, servo: {id: 1}}
)"),
              HasSubstr("servo id 1 is already joint yaw's"));
  EXPECT_THAT(ErrorOf(kCameras + kJoints + "colour: red\n"), HasSubstr("colour"));
}

TEST_F(HeadFileTest, AMimicWhoseLimitsLeaveItsSourceNoValueIsRefused) {
  // vergence = -2 * yaw within [2.5, 3] needs yaw in [-1.5, -1.25], outside yaw's [-1, 1]: no
  // posture respects both (the limits folded to min > max before, and HomePosture clamped
  // into an empty range).
  std::ifstream in(folder_ / "head.urdf");
  std::string urdf((std::istreambuf_iterator<char>(in)), {});
  const std::string range = R"(lower="-0.6" upper="0.6")";
  urdf.replace(urdf.find(range), range.size(), R"(lower="2.5" upper="3")");
  std::ofstream(folder_ / "head.urdf") << urdf;
  EXPECT_THAT(ErrorOf(kCameras + kJoints),
              AllOf(HasSubstr("head.urdf"), HasSubstr("joint vergence"),
                    HasSubstr("as a mimic of 'yaw'"), HasSubstr("expected ranges that overlap")));
}

}  // namespace
}  // namespace saccade::head
