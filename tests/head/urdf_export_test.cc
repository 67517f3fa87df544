#include "saccade/head/urdf_export.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "saccade/head/urdf.h"

namespace saccade::head {
namespace {

namespace fs = std::filesystem;
using geometry::Pose;
using ::testing::AllOf;
using ::testing::HasSubstr;

// The URDF carries every number in its shortest exact text, so only the rpy <-> rotation
// conversions (of origins and of the Gazebo <pose>) round: a few ulps of ~1 m poses.
constexpr double kPoseTolerance = 1e-12;
// fx = width / 2 / tan(horizontal_fov / 2) after horizontal_fov = 2 atan(width / 2 / fx): the
// tangent of the arctangent rounds by a few ulps (relative).
constexpr double kFocalTolerance = 1e-12;
constexpr int kPostures = 1000;

const fs::path kSource = SACCADE_SOURCE_DIR;

// A legacy head with every offset of appendix A non-zero and a turned base (fuzz seed
// calibrated.yaml's geometry), with cameras Gazebo can express.
const std::string kOffsetHead = R"(name: offsets
geometry: {half_baseline: 0.06, D: 0.02, H: 0.01, delta_left: 0.005, delta_right: -0.004}
joints:
  pan: {limits: [-1.5, 1.5], max_velocity: 5, max_acceleration: 50}
  tilt: {limits: [-0.7, 0.7], max_velocity: 5, max_acceleration: 50}
  left: {limits_deg: [-40, 40], max_velocity_deg: 500, max_acceleration_deg: 5000}
  right: {limits_deg: [-40, 40], max_velocity_deg: 500, max_acceleration_deg: 5000}
pose: {position: [0.1, -0.2, 1.3], rpy: [0.01, -0.02, 0.3]}
cameras:
  left: {width: 640, height: 480, fx: 520.5, fy: 520.5, cx: 319.5, cy: 239.5,
         distortion: {model: radtan, coefficients: [-0.28, 0.07, 0.001, -0.0005, 0.01]}}
  right: {width: 800, height: 600, fx: 610.25, fy: 610.25, cx: 399.5, cy: 299.5}
)";

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / fmt::format("saccade_urdf_export_test_{}_{}", ::getpid(), name);
  fs::create_directories(dir);
  return dir;
}

void WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

double PoseDifference(const Pose& a, const Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

// A head file naming the exported URDF and its Gazebo sensors, with what a URDF cannot hold
// (the pose, the accelerations) from the original.
std::string HeadFileFor(const HeadModel& head, const std::string& urdf) {
  const Eigen::Vector3d rpy = geometry::RpyFromRotation(head.X_WB().linear());
  std::string text = fmt::format(
      "name: {}\nurdf: {}\npose: {{position: [{}, {}, {}], rpy: [{}, {}, {}]}}\n"
      "cameras:\n  left: {{gazebo_sensor: left_camera}}\n  right: {{gazebo_sensor: "
      "right_camera}}\njoints:\n",
      head.name(), urdf, head.X_WB().translation().x(), head.X_WB().translation().y(),
      head.X_WB().translation().z(), rpy.x(), rpy.y(), rpy.z());
  for (int i = 0; i < head.num_joints(); ++i) {
    text += fmt::format("  {}: {{max_acceleration: {}}}\n", head.joint_name(i),
                        head.joint(i).limits.max_acceleration);
  }
  return text;
}

// Exports `original`, reads the URDF back through a head file, and checks the two heads agree.
void ExpectRoundTrip(const HeadModel& original, const std::string& tag) {
  const UrdfExport exported = ExportUrdf(original);
  EXPECT_THAT(exported.warnings, ::testing::IsEmpty());
  const fs::path dir = TempDir(tag);
  WriteFile(dir / "exported.urdf", exported.xml);
  WriteFile(dir / "exported.yaml", HeadFileFor(original, "exported.urdf"));

  // urdfdom reads it, with both sensors.
  const UrdfModel urdf = ParseUrdf(exported.xml, "exported.urdf", dir);
  EXPECT_EQ(urdf.name, original.name());
  ASSERT_NE(urdf.FindCamera("left_camera"), nullptr);
  ASSERT_NE(urdf.FindCamera("right_camera"), nullptr);

  const HeadModel back = HeadModel::FromFile(dir / "exported.yaml");
  const KinematicTree& a = original.tree();
  const KinematicTree& b = back.tree();
  ASSERT_EQ(b.num_links(), a.num_links());
  for (int l = 0; l < a.num_links(); ++l) EXPECT_EQ(b.link_name(l), a.link_name(l));
  ASSERT_EQ(b.num_joints(), a.num_joints());
  ASSERT_EQ(back.num_joints(), original.num_joints());
  for (int i = 0; i < original.num_joints(); ++i) {
    SCOPED_TRACE(original.joint_name(i));
    EXPECT_EQ(back.joint_name(i), original.joint_name(i));
    const JointLimits& x = original.joint(i).limits;
    const JointLimits& y = back.joint(i).limits;
    EXPECT_EQ(y.min, x.min);
    EXPECT_EQ(y.max, x.max);
    EXPECT_EQ(y.max_velocity, x.max_velocity);
    EXPECT_EQ(y.max_acceleration, x.max_acceleration);
  }
  for (int j = 0; j < a.num_joints(); ++j) {
    EXPECT_EQ(b.joint(j).name, a.joint(j).name);
    EXPECT_EQ(b.joint(j).type, a.joint(j).type);
  }

  std::mt19937_64 random(42);
  std::vector<Pose> X_a, X_b;
  double worst_link = 0.0, worst_camera = 0.0;
  for (int n = 0; n < kPostures; ++n) {
    Eigen::VectorXd q(original.num_joints());
    for (int i = 0; i < q.size(); ++i) {
      const JointLimits& l = original.joint(i).limits;
      q[i] = std::uniform_real_distribution<double>(l.min, l.max)(random);
    }
    original.ForwardKinematics(q, &X_a);
    back.ForwardKinematics(q, &X_b);
    for (int l = 0; l < a.num_links(); ++l) {
      worst_link = std::max(worst_link, PoseDifference(X_a[l], X_b[l]));
    }
    for (int eye = 0; eye < 2; ++eye) {
      worst_camera = std::max(
          worst_camera, PoseDifference(original.CameraPose(eye, X_a), back.CameraPose(eye, X_b)));
    }
  }
  EXPECT_LT(worst_link, kPoseTolerance);
  EXPECT_LT(worst_camera, kPoseTolerance);

  for (int eye = 0; eye < 2; ++eye) {
    SCOPED_TRACE(eye == 0 ? "left" : "right");
    const geometry::Intrinsics& k = original.camera(eye).model.intrinsics();
    const geometry::Intrinsics& m = back.camera(eye).model.intrinsics();
    EXPECT_EQ(m.width(), k.width());
    EXPECT_EQ(m.height(), k.height());
    EXPECT_NEAR(m.fx(), k.fx(), kFocalTolerance * k.fx());
    EXPECT_NEAR(m.fy(), k.fy(), kFocalTolerance * k.fy());
    EXPECT_EQ(m.cx(), k.cx());
    EXPECT_EQ(m.cy(), k.cy());
    EXPECT_EQ(m.skew(), 0.0);
    EXPECT_EQ(back.camera(eye).model.distortion(), original.camera(eye).model.distortion());
  }
  fs::remove_all(dir);
}

TEST(UrdfExport, PopeyesLegacyHeadComesBackFromItsUrdfWithTheSameKinematicsAndCameras) {
  const HeadModel popeye = HeadModel::FromFile(kSource / "robots/popeye.yaml");
  ASSERT_TRUE(popeye.urdf_xml().empty());
  ExpectRoundTrip(popeye, "popeye");
}

TEST(UrdfExport, ALegacyHeadWithEveryOffsetAndADistortedCameraComesBackTheSame) {
  const HeadModel head = HeadModel::FromYamlString(kOffsetHead, "offsets.yaml", kSource);
  ASSERT_NE(head.camera(0).model.distortion().model(), geometry::DistortionModel::kNone);
  ExpectRoundTrip(head, "offsets");
}

TEST(UrdfExport, TheUrdfHasFourRevoluteJointsInTheTreesOrderAndNoVisuals) {
  const HeadModel popeye = HeadModel::FromFile(kSource / "robots/popeye.yaml");
  const std::string xml = ExportUrdf(popeye).xml;
  const UrdfModel urdf = ParseUrdf(xml, "popeye.urdf", kSource);
  ASSERT_EQ(urdf.tree.num_variables(), 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(urdf.tree.variable_name(i), popeye.joint_name(i));
    EXPECT_EQ(urdf.tree.joint(urdf.tree.variable_joint(i)).type, JointType::kRevolute);
  }
  EXPECT_TRUE(urdf.visuals.empty());
  EXPECT_THAT(xml, HasSubstr("<gazebo reference=\"left_camera_optical\">"));
  EXPECT_THAT(xml, HasSubstr("<sensor type=\"camera\" name=\"right_camera\">"));
}

TEST(UrdfExport, AHeadFromAUrdfGetsItsTextUnchanged) {
  const HeadModel humanoid = HeadModel::FromFile(kSource / "robots/humanoid.yaml");
  const UrdfExport exported = ExportUrdf(humanoid);
  EXPECT_EQ(exported.xml, humanoid.urdf_xml());
  EXPECT_TRUE(exported.warnings.empty());
}

TEST(UrdfExport, ACameraWithFxNotFyIsWrittenWithFxAndAWarning) {
  std::string text = kOffsetHead;
  const std::string exact = "fx: 520.5, fy: 520.5";
  text.replace(text.find(exact), exact.size(), "fx: 520.5, fy: 530");
  const HeadModel head = HeadModel::FromYamlString(text, "fy.yaml", kSource);
  const UrdfExport exported = ExportUrdf(head);
  ASSERT_EQ(exported.warnings.size(), 1u);
  EXPECT_THAT(exported.warnings[0],
              AllOf(HasSubstr("left camera"), HasSubstr("fx 520.5 != fy 530"), HasSubstr("fx")));
  EXPECT_THAT(exported.xml, HasSubstr("<!-- not exact: fx 520.5 != fy 530"));
  // The sensor is still there, with the horizontal field of view of fx.
  const UrdfModel urdf = ParseUrdf(exported.xml, "fy.urdf", kSource);
  const GazeboCamera* left = urdf.FindCamera("left_camera");
  ASSERT_NE(left, nullptr);
  EXPECT_NEAR(left->Model().intrinsics().fx(), 520.5, kFocalTolerance * 520.5);
  EXPECT_EQ(left->Model().intrinsics().cx(), 319.5);
}

TEST(UrdfExport, EveryPropertyGazeboLacksIsNamed) {
  // Off-centre principal point, skew, a rational k6 (left); fisheye (right).
  std::ifstream file(kSource / "fuzz/corpus/head/calibrated.yaml");
  const std::string text((std::istreambuf_iterator<char>(file)), {});
  const HeadModel head = HeadModel::FromYamlString(text, "calibrated.yaml", kSource);
  const UrdfExport exported = ExportUrdf(head);
  const auto joined = fmt::format("{}", fmt::join(exported.warnings, "\n"));
  EXPECT_EQ(exported.warnings.size(), 5u) << joined;
  EXPECT_THAT(joined, AllOf(HasSubstr("fx 520.5 != fy 519.8"), HasSubstr("principal point"),
                            HasSubstr("skew 0.3"), HasSubstr("k4 k5 k6"),
                            HasSubstr("right camera (sensor right_camera): fisheye")));
  // Still a URDF saccade reads, with the first five coefficients of the left camera.
  const UrdfModel urdf = ParseUrdf(exported.xml, "calibrated.urdf", kSource);
  const GazeboCamera* left = urdf.FindCamera("left_camera");
  ASSERT_NE(left, nullptr);
  EXPECT_EQ(left->distortion, (std::array<double, 5>{-0.28, 0.07, 0.001, -0.0005, 0.01}));
  EXPECT_EQ(urdf.FindCamera("right_camera")->distortion, (std::array<double, 5>{}));
}

}  // namespace
}  // namespace saccade::head
