// The robot on ROS 2's wire, as robot_state_publisher would send it (issue 42): the head's URDF
// on robot_description (std_msgs/String, reliable, transient local, keep last 1) for readers
// that come later, and TF for every link of any head, read by a plain Cyclone DDS reader of the
// tests' own types.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "dds_test_util.h"
#include "saccade/components/register.h"
#include "saccade/dds/transport.h"
#include "saccade/head/head_model.h"
#include "saccade/head/urdf_export.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"

namespace saccade::dds {
namespace {

using namespace saccade::dds::testing;
namespace fs = std::filesystem;

const std::string kSource = SACCADE_SOURCE_DIR;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A head alone, publishing its joints for 5 steps in `domain`.
std::string HeadPipeline(int domain) {
  return "clock: {mode: simulated, step: 0.04, steps: 5}\nscene: " + kSource +
         "/scenes/portraits.yaml\ntransport: {domain: " + std::to_string(domain) +
         ", namespace: /saccade}\ncomponents:\n  - name: head\n    type: sim.head\n    outputs: "
         "{joints: joint_states}\n";
}

geometry::Pose PoseOf(const ref_geometry_msgs_msg_dds__Transform_& t) {
  const Eigen::Quaterniond q(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z);
  geometry::Pose pose = geometry::Pose::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  return pose;
}

class RobotState : public ::testing::Test {
 protected:
  void SetUp() override {
    PinLoopback();
    components::RegisterComponents();
    RegisterDdsTransport(runtime::ComponentRegistry::Global());
  }

  // Runs the head pipeline with `head_file` (empty: the scene's POPEYE), then joins as a late
  // reader and checks robot_description and the TF of every link against the head's own FK.
  void CheckLateJoiner(int domain, const std::string& head_file, const std::string& expected_urdf) {
    const head::HeadModel head =
        head::HeadModel::FromFile(head_file.empty() ? kSource + "/robots/popeye.yaml" : head_file);
    const runtime::PipelineSpec spec = runtime::ParsePipeline(HeadPipeline(domain), "h.yaml");
    runtime::Pipeline pipeline =
        head_file.empty()
            ? runtime::Pipeline::Build(spec)
            : runtime::Pipeline::Build(spec, components::RegistryWithHead(head_file, "--head"));
    const runtime::RunSummary summary = runtime::RunPipeline(pipeline);
    ASSERT_EQ(summary.errors_total, 0) << summary.FullReport();

    // Late: the publisher ran all its steps before this reader existed.
    Raw raw(RawParticipant(domain));
    Raw description(RawReader(raw.get(), &ref_std_msgs_msg_dds__String__desc,
                              "rt/saccade/robot_description", 1, /*transient_local=*/true));
    Raw tf(RawReader(raw.get(), &ref_tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", 100,
                     /*transient_local=*/true));
    ref_std_msgs_msg_dds__String_ text{};
    ASSERT_TRUE(TakeSample(description.get(), &text)) << "no robot_description for a late joiner";
    EXPECT_EQ(std::string(text.data), expected_urdf);
    dds_sample_free(&text, &ref_std_msgs_msg_dds__String__desc, DDS_FREE_CONTENTS);
    // Only one description (keep last 1, written once).
    ref_std_msgs_msg_dds__String_ again{};
    EXPECT_FALSE(TakeSample(description.get(), &again, 0.3));

    // Each step's TF: world -> root, and one transform per joint; composed from the world they
    // give every link where the head's forward kinematics puts it (the head stays at home).
    std::vector<geometry::Pose> X_WL;
    head.ForwardKinematics(head.HomePosture(), &X_WL);
    const head::KinematicTree& tree = head.tree();
    int messages = 0;
    for (ref_tf2_msgs_msg_dds__TFMessage_ message{};
         TakeSample(tf.get(), &message, messages == 0 ? 10.0 : 0.5);) {
      ++messages;
      ASSERT_EQ(static_cast<int>(message.transforms._length), tree.num_joints() + 1);
      // Stamped with the joints' time, oldest first: the end of each of the 5 steps of 0.04 s.
      EXPECT_EQ(message.transforms._buffer[0].header.stamp.sec, 0);
      EXPECT_EQ(message.transforms._buffer[0].header.stamp.nanosec, 40000000u * messages);
      std::map<std::string, geometry::Pose> world;  // parents come first (tree order)
      world["world"] = geometry::Pose::Identity();
      for (uint32_t i = 0; i < message.transforms._length; ++i) {
        const auto& t = message.transforms._buffer[i];
        const std::string parent = t.header.frame_id, child = t.child_frame_id;
        ASSERT_TRUE(world.contains(parent)) << parent << " before its parent";
        EXPECT_FALSE(world.contains(child)) << child << " has two parents";
        world[child] = world[parent] * PoseOf(t.transform);
      }
      for (int link = 0; link < tree.num_links(); ++link) {
        SCOPED_TRACE(tree.link_name(link));
        ASSERT_TRUE(world.contains(tree.link_name(link)));
        const geometry::Pose& got = world[tree.link_name(link)];
        EXPECT_LT((got.translation() - X_WL[link].translation()).norm(), 1e-9);
        EXPECT_LT((got.linear() - X_WL[link].linear()).norm(), 1e-9);
      }
      dds_sample_free(&message, &ref_tf2_msgs_msg_dds__TFMessage__desc, DDS_FREE_CONTENTS);
      message = {};
    }
    // The writer keeps its last 100 (tf's depth, transient local): a late joiner gets all 5.
    EXPECT_EQ(messages, 5);
  }
};

TEST_F(RobotState, AHumanoidsUrdfAndEveryLinkReachALateJoiner) {
  const std::string head = kSource + "/robots/humanoid.yaml";
  CheckLateJoiner(231, head, ReadText(kSource + "/robots/humanoid/humanoid.urdf"));
}

TEST_F(RobotState, PopeyesLegacyHeadSendsTheUrdfSaccadeWrites) {
  const head::HeadModel popeye = head::HeadModel::FromFile(kSource + "/robots/popeye.yaml");
  CheckLateJoiner(232, "", head::ExportUrdf(popeye).xml);
}

TEST_F(RobotState, TheCoupledVergenceHeadToo) {
  const std::string head = kSource + "/robots/pan_tilt_vergence.yaml";
  CheckLateJoiner(230, head,
                  ReadText(kSource + "/robots/pan_tilt_vergence/pan_tilt_vergence.urdf"));
}

}  // namespace
}  // namespace saccade::dds
