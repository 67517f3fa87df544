#include "saccade/head/urdf.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>

#include "saccade/core/error.h"

namespace saccade::head {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::AnyOf;
using ::testing::HasSubstr;

// Rotations built from rpy through urdfdom's quaternion round off at ~1e-16.
constexpr double kRotationTolerance = 1e-15;

// A pan-tilt head with its two parts; `extra` goes inside <robot>.
std::string Robot(const std::string& tilt_joint_body, const std::string& extra = "") {
  return R"(<?xml version="1.0"?>
<robot name="test_head">
  <link name="base"/>
  <link name="neck"/>
  <link name="head"/>
  <joint name="pan" type="revolute">
    <parent link="base"/><child link="neck"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="2"/>
  </joint>
  <joint name="tilt" type="revolute">
)" + tilt_joint_body +
         R"(
  </joint>
)" + extra +
         "</robot>\n";
}

const std::string kGoodTilt = R"(    <parent link="neck"/><child link="head"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="2"/>)";

std::string ErrorOf(const std::string& xml, const UrdfOptions& options = {}) {
  try {
    ParseUrdf(xml, "robots/test.urdf", ".", options);
  } catch (const FileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Urdf, AGoodRobotGivesItsTreeLimitsAndTheDocumentsJointOrder) {
  const UrdfModel robot = ParseUrdf(Robot(kGoodTilt), "robots/test.urdf", ".");
  EXPECT_EQ(robot.name, "test_head");
  ASSERT_EQ(robot.tree.num_variables(), 2);
  EXPECT_EQ(robot.tree.variable_name(0), "pan");  // document order, not urdfdom's sorted map
  EXPECT_EQ(robot.tree.variable_name(1), "tilt");
  EXPECT_EQ(robot.tree.joint(robot.tree.FindJoint("tilt")).upper, 0.5);
  EXPECT_EQ(robot.tree.joint(robot.tree.FindJoint("tilt")).max_velocity, 2.0);
  EXPECT_EQ(robot.xml, Robot(kGoodTilt));
}

TEST(Urdf, TextThatIsNotXmlIsRefusedWithTheLine) {
  EXPECT_THAT(ErrorOf("<robot name='x'>\n<link name='a'>\n</robot>"),
              AllOf(HasSubstr("robots/test.urdf:"), HasSubstr("expected a URDF file")));
}

TEST(Urdf, XmlThatIsNotUrdfIsRefused) {
  EXPECT_THAT(ErrorOf("<?xml version='1.0'?>\n<sdf version='1.6'><model name='m'/></sdf>"),
              AllOf(HasSubstr("robots/test.urdf:2: robot:"), HasSubstr("root element is <sdf>"),
                    HasSubstr("expected <robot>")));
}

TEST(Urdf, WhatUrdfdomRefusesIsQuoted) {
  // A joint whose child link does not exist: urdfdom refuses the tree.
  EXPECT_THAT(ErrorOf(Robot(R"(<parent link="neck"/><child link="skull"/>
    <axis xyz="0 1 0"/><limit lower="-0.5" upper="0.5" effort="1" velocity="2"/>)")),
              AllOf(HasSubstr("robots/test.urdf:10: joint tilt:"), HasSubstr("urdfdom"),
                    HasSubstr("skull")));
}

TEST(Urdf, AZeroAxisIsRefusedWithTheJointsLine) {
  EXPECT_THAT(ErrorOf(Robot(R"(<parent link="neck"/><child link="head"/>
    <axis xyz="0 0 0"/><limit lower="-0.5" upper="0.5" effort="1" velocity="2"/>)")),
              AllOf(HasSubstr("robots/test.urdf:10: joint tilt:"), HasSubstr("must not be zero")));
}

TEST(Urdf, ACycleOfJointsIsRefusedNamingItsLinksBeforeUrdfdomLeaksIt) {
  // urdfdom links a cycle into shared pointers it never frees (fuzz/urdf_fuzzer found the leak)
  // and says only "no root link"; neck has two parents here, pan's and back's.
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt, R"(  <joint name="back" type="fixed">
    <parent link="head"/><child link="neck"/></joint>
)")),
              AllOf(HasSubstr("robots/test.urdf:"), HasSubstr("joint "),
                    HasSubstr("the joints form a cycle of links"), HasSubstr("expected a tree")));
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt, R"(  <joint name="back" type="fixed">
    <parent link="head"/><child link="neck"/></joint>
)")),
              AnyOf(HasSubstr("(neck -> head -> neck)"), HasSubstr("(head -> neck -> head)")));
}

TEST(Urdf, LimitsWithLowerAboveUpperAreRefused) {
  EXPECT_THAT(
      ErrorOf(Robot(R"(<parent link="neck"/><child link="head"/>
    <axis xyz="0 1 0"/><limit lower="0.5" upper="-0.5" effort="1" velocity="2"/>)")),
      AllOf(HasSubstr("robots/test.urdf:10: joint tilt:"), HasSubstr("expected lower <= upper")));
}

TEST(Urdf, NanLimitsAreRefused) {
  EXPECT_THAT(ErrorOf(Robot(R"(<parent link="neck"/><child link="head"/>
    <axis xyz="0 1 0"/><limit lower="nan" upper="0.5" effort="1" velocity="2"/>)")),
              AllOf(HasSubstr("robots/test.urdf:10: joint tilt:"), HasSubstr("urdfdom"),
                    HasSubstr("lower value (nan) is not a valid float")));
}

TEST(Urdf, AFloatingJointIsRefused) {
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt, R"(<link name="free"/>
  <joint name="drift" type="floating"><parent link="head"/><child link="free"/></joint>
)")),
              AllOf(HasSubstr("joint drift"), HasSubstr("expected revolute, continuous")));
}

const std::string kCamera = R"(<link name="camera_link"/>
  <joint name="camera_mount" type="fixed">
    <parent link="head"/><child link="camera_link"/><origin xyz="0.05 0.03 0"/>
  </joint>
  <gazebo reference="camera_link">
    <sensor type="camera" name="left_camera">
      <pose>0.01 0 0.02 0 0.1 0</pose>
      <camera>
        <horizontal_fov>1.047</horizontal_fov>
        <image><width>640</width><height>480</height><format>R8G8B8</format></image>
        <clip><near>0.05</near><far>30</far></clip>
        <distortion><k1>-0.02</k1><k2>0.01</k2><k3>0.001</k3><p1>0.0005</p1><p2>-0.0004</p2>
          <center>0.5 0.5</center></distortion>
      </camera>
    </sensor>
  </gazebo>
)";

TEST(Urdf, AGazeboCameraHasGazebosIntrinsics) {
  const UrdfModel robot = ParseUrdf(Robot(kGoodTilt, kCamera), "robots/test.urdf", ".");
  ASSERT_EQ(robot.cameras.size(), 1u);
  const GazeboCamera& camera = *robot.FindCamera("left_camera");
  EXPECT_EQ(camera.link, "camera_link");
  EXPECT_EQ(camera.near, 0.05);
  EXPECT_EQ(camera.far, 30.0);
  const geometry::CameraModel model = camera.Model();
  // Gazebo's formula, evaluated the same way: equal to the last bit.
  EXPECT_EQ(model.intrinsics().fx(), 640 / 2.0 / std::tan(1.047 / 2.0));
  EXPECT_EQ(model.intrinsics().fy(), model.intrinsics().fx());
  EXPECT_EQ(model.intrinsics().cx(), 319.5);
  EXPECT_EQ(model.intrinsics().cy(), 239.5);
  EXPECT_EQ(model.intrinsics().width(), 640);
  // OpenCV's order k1 k2 p1 p2 k3.
  const std::vector<double> expected = {-0.02, 0.01, 0.0005, -0.0004, 0.001};
  const auto coefficients = model.distortion().coefficients();
  ASSERT_GE(coefficients.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(coefficients[i], expected[i]) << i;
  // The optical frame: Gazebo's camera frame (x forward, z up) turned to x right, y down.
  const geometry::Pose X_LO = camera.X_LOptical();
  const Eigen::Matrix3d R_LS = geometry::RotationFromRpy(0, 0.1, 0);
  EXPECT_LE((X_LO.linear().col(2) - R_LS.col(0)).norm(), kRotationTolerance);  // z = forward
  EXPECT_LE((X_LO.linear().col(0) + R_LS.col(1)).norm(), kRotationTolerance);  // x = -left
  EXPECT_LE((X_LO.linear().col(1) + R_LS.col(2)).norm(), kRotationTolerance);  // y = -up
  EXPECT_EQ(X_LO.translation(), Eigen::Vector3d(0.01, 0, 0.02));
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(Urdf, ABadGazeboCameraIsRefusedNamingTheSensor) {
  EXPECT_THAT(
      ErrorOf(Robot(kGoodTilt, Replace(kCamera, "<width>640</width>", ""))),
      AllOf(HasSubstr("robots/test.urdf:"), HasSubstr("gazebo sensor left_camera image width"),
            HasSubstr("expected <image><width> in pixels")));
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt,
                            Replace(kCamera, "reference=\"camera_link\"", "reference=\"camera\""))),
              AllOf(HasSubstr("gazebo sensor left_camera"),
                    HasSubstr("reference link \"camera\" does not exist")));
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt, Replace(kCamera, "1.047", "3.5"))),
              HasSubstr("expected <horizontal_fov> in radians, in (0, pi)"));
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt, Replace(kCamera, "<pose>0.01 0 0.02 0 0.1 0</pose>",
                                               "<pose>0.01 0 0.02</pose>"))),
              AllOf(HasSubstr("gazebo sensor left_camera pose"), HasSubstr("expected 6 numbers")));
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt, Replace(kCamera, "<near>0.05</near>", "<near>40</near>"))),
              HasSubstr("expected 0 < near < far"));
  EXPECT_THAT(ErrorOf(Robot(kGoodTilt, Replace(kCamera, "0.5 0.5", "0.4 0.5"))),
              HasSubstr("saccade supports the image centre"));
}

// A scratch folder under the system's temporary folder, removed at the end.
class ScratchFolder {
 public:
  ScratchFolder()
      : path_(fs::temp_directory_path() / ("saccade-urdf-test-" + std::to_string(getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchFolder() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }
  void Write(const fs::path& relative, const std::string& text) const {
    fs::create_directories((path_ / relative).parent_path());
    std::ofstream(path_ / relative) << text;
  }

 private:
  fs::path path_;
};

std::string MeshVisual(const std::string& uri) {
  return R"(<link name="shell"><visual><origin xyz="0 0 0.05"/><geometry><mesh filename=")" + uri +
         R"(" scale="2 2 2"/></geometry><material name="grey"><color rgba="0.5 0.5 0.5 1"/></material></visual></link>
  <joint name="shell_mount" type="fixed"><parent link="head"/><child link="shell"/></joint>
)";
}

TEST(Urdf, PackageUrisResolveThroughRosPackagePathAndTheHeadFilesPackages) {
  ScratchFolder scratch;
  scratch.Write("ws/my_head/meshes/shell.stl", "solid s\nendsolid s\n");
  scratch.Write("robot/head.urdf",
                Robot(kGoodTilt, MeshVisual("package://my_head/meshes/shell.stl")));
  const fs::path urdf = scratch.path() / "robot/head.urdf";
  // Not found: the message names the URI and where it looked.
  try {
    LoadUrdfFile(urdf);
    FAIL() << "expected an error";
  } catch (const FileError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("head.urdf:"), HasSubstr("link shell visual"),
                                HasSubstr("mesh \"package://my_head/meshes/shell.stl\" not found"),
                                HasSubstr("robot/my_head/meshes/shell.stl")));
  }
  // Optional visuals: left out.
  UrdfOptions optional;
  optional.visuals_optional = true;
  EXPECT_TRUE(LoadUrdfFile(urdf, optional).visuals.empty());
  // ROS's convention: a folder of $ROS_PACKAGE_PATH holds the package's folder.
  const std::string workspace = (scratch.path() / "ws").string();
  setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + workspace).c_str(), 1);
  const UrdfModel robot = LoadUrdfFile(urdf);
  unsetenv("ROS_PACKAGE_PATH");
  ASSERT_EQ(robot.visuals.size(), 1u);
  const UrdfVisual& visual = robot.visuals[0];
  EXPECT_EQ(visual.mesh_path, scratch.path() / "ws/my_head/meshes/shell.stl");
  EXPECT_EQ(visual.scale, Eigen::Vector3d(2, 2, 2));
  EXPECT_EQ(visual.rgba, Eigen::Vector4d(0.5, 0.5, 0.5, 1));
  EXPECT_EQ(robot.tree.link_name(visual.link), "shell");
  // The head file's `packages:` map.
  UrdfOptions named;
  named.packages["my_head"] = scratch.path() / "ws/my_head";
  EXPECT_EQ(LoadUrdfFile(urdf, named).visuals[0].mesh_path,
            scratch.path() / "ws/my_head/meshes/shell.stl");
}

TEST(Urdf, RelativeMeshPathsAreRelativeToTheUrdfsFolder) {
  ScratchFolder scratch;
  scratch.Write("robot/meshes/shell.obj", "v 0 0 0\n");
  scratch.Write("robot/head.urdf", Robot(kGoodTilt, MeshVisual("meshes/shell.obj")));
  EXPECT_EQ(LoadUrdfFile(scratch.path() / "robot/head.urdf").visuals[0].mesh_path,
            scratch.path() / "robot/meshes/shell.obj");
}

TEST(Urdf, PrimitiveVisualsKeepTheirSizes) {
  const UrdfModel robot = ParseUrdf(Robot(kGoodTilt, R"(<link name="parts">
    <visual><geometry><box size="0.1 0.2 0.3"/></geometry></visual>
    <visual><geometry><cylinder radius="0.02" length="0.5"/></geometry></visual>
    <visual><geometry><sphere radius="0.04"/></geometry></visual>
  </link>
  <joint name="parts_mount" type="fixed"><parent link="head"/><child link="parts"/></joint>
)"),
                                    "robots/test.urdf", ".");
  ASSERT_EQ(robot.visuals.size(), 3u);
  EXPECT_EQ(robot.visuals[0].shape, UrdfVisual::Shape::kBox);
  EXPECT_EQ(robot.visuals[0].size, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(robot.visuals[1].shape, UrdfVisual::Shape::kCylinder);
  EXPECT_EQ(robot.visuals[1].size, Eigen::Vector3d(0.02, 0.02, 0.5));
  EXPECT_EQ(robot.visuals[2].shape, UrdfVisual::Shape::kSphere);
  EXPECT_FALSE(robot.visuals[2].rgba.has_value());
}

TEST(Urdf, AMissingFileIsAnError) {
  EXPECT_THROW(LoadUrdfFile("/nonexistent/head.urdf"), FileError);
}

}  // namespace
}  // namespace saccade::head
