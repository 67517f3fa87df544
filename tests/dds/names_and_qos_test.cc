// ROS 2 topic names and QoS profiles: what is accepted, and the errors for what is not.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "dds_test_util.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/qos.h"
#include "saccade/dds/topic_names.h"
#include "saccade/dds/topics.h"
#include "saccade/dds/transport.h"

namespace saccade::dds {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(TopicNames, ResolveAsRos2Does) {
  EXPECT_EQ(ResolveTopic("left/image_raw", "/saccade"), "/saccade/left/image_raw");
  EXPECT_EQ(ResolveTopic("left/image_raw", "saccade/"), "/saccade/left/image_raw");
  EXPECT_EQ(ResolveTopic("/tf", "/saccade"), "/tf");
  EXPECT_EQ(ResolveTopic("joint_states", ""), "/joint_states");
  EXPECT_EQ(DdsTopicName("/saccade/left/image_raw"), "rt/saccade/left/image_raw");
  EXPECT_EQ(SiblingTopic("/saccade/left/image_raw", "camera_info"), "/saccade/left/camera_info");
}

TEST(TopicNames, BadNamesSayWhatIsWrong) {
  EXPECT_THAT(ErrorOf([] { ResolveTopic("left image", "/saccade"); }),
              HasSubstr("topic 'left image': character ' ' is not allowed"));
  EXPECT_THAT(ErrorOf([] { ResolveTopic("/saccade//left", ""); }), HasSubstr("empty token"));
  EXPECT_THAT(ErrorOf([] { ResolveTopic("/saccade/2d", ""); }),
              HasSubstr("token '2d' starts with a digit"));
  EXPECT_THAT(ErrorOf([] { ResolveTopic("left/", ""); }), HasSubstr("must not end with '/'"));
  EXPECT_THAT(ErrorOf([] { ResolveTopic("~/image", ""); }), HasSubstr("substitutions"));
  EXPECT_THAT(ErrorOf([] { ResolveTopic("", ""); }), HasSubstr("must not be empty"));
  EXPECT_THAT(ErrorOf([] { DdsTopicName("left/image"); }), HasSubstr("must start with '/'"));
}

TEST(Qos, ProfilesAreRos2s) {
  EXPECT_EQ(Qos::SensorData(), (Qos{Reliability::kBestEffort, Durability::kVolatile, 5}));
  EXPECT_EQ(Qos::Default(), (Qos{Reliability::kReliable, Durability::kVolatile, 10}));
  EXPECT_EQ(ParseQos("sensor_data", "qos"), Qos::SensorData());
  EXPECT_EQ(ParseQos(json{{"profile", "sensor_data"}, {"depth", 1}}, "qos"),
            (Qos{Reliability::kBestEffort, Durability::kVolatile, 1}));
  EXPECT_EQ(ParseQos(json{{"durability", "transient_local"}}, "qos"),
            (Qos{Reliability::kReliable, Durability::kTransientLocal, 10}));
  EXPECT_EQ(Qos::Images().reliability, Reliability::kReliable);
}

TEST(Qos, BadQosSaysWhatIsWrong) {
  EXPECT_THAT(ErrorOf([] { ParseQos("fast", "inputs.image.qos"); }),
              HasSubstr("inputs.image.qos: unknown QoS profile 'fast'; expected one of "
                        "sensor_data, default, images, latched"));
  EXPECT_THAT(ErrorOf([] {
                ParseQos(json{{"depth", 0}}, "qos");
              }),
              HasSubstr("qos.depth: expected an integer 1..1000, got 0"));
  EXPECT_THAT(ErrorOf([] {
                ParseQos(json{{"reliability", "sometimes"}}, "qos");
              }),
              HasSubstr("qos.reliability: expected reliable or best_effort, got \"sometimes\""));
  EXPECT_THAT(ErrorOf([] {
                ParseQos(json{{"history", 3}}, "qos");
              }),
              HasSubstr("qos.history: unknown QoS key"));
  EXPECT_THAT(ErrorOf([] { ParseQos(json(3), "qos"); }), HasSubstr("expected a QoS profile name"));
}

TEST(Topics, WritersRefuseWhatHasNoRosForm) {
  testing::PinLoopback();
  auto participant = Participant::Create(testing::Domain(171));
  EXPECT_THAT(
      ErrorOf([&] { Writer::Create(participant, "vision.faces", testing::Topic("/faces")); }),
      HasSubstr("message type 'vision.faces' has no ROS 2 form; DDS topics carry "
                "runtime.image (sensor_msgs/msg/Image)"));
  EXPECT_THAT(
      ErrorOf([&] { Writer::Create(participant, "head.joints", testing::Topic("joints")); }),
      HasSubstr("topic 'joints': a ROS topic name must start with '/'"));
  EXPECT_THAT(ErrorOf([&] {
                Reader::Create(participant, "head.joints",
                               testing::Topic("/joints", Qos{Reliability::kReliable,
                                                             Durability::kVolatile, 0}));
              }),
              HasSubstr("QoS of /joints: depth must be 1..1000, got 0"));
}

TEST(Participants, OptionsAreChecked) {
  EXPECT_THAT(ErrorOf([] { CycloneConfigXml(testing::Domain(300)); }),
              HasSubstr("domain id must be 0..232, got 300"));
  EXPECT_THAT(ErrorOf([] { CycloneConfigXml(testing::Domain(0, "network")); }),
              HasSubstr("the network config needs an interface"));
  EXPECT_THAT(ErrorOf([] { CycloneConfigXml(testing::Domain(0, "wifi")); }),
              HasSubstr("config must be loopback, network, env or a path"));
  // The default keeps to loopback; the network one names the interface and the peers.
  EXPECT_THAT(CycloneConfigXml({}), HasSubstr("<NetworkInterface name=\"lo\"/>"));
  DomainOptions options = testing::Domain(0, "network");
  options.interface = "eth1";
  options.peers = {"robot.local"};
  const std::string network = CycloneConfigXml(options);
  EXPECT_THAT(network, HasSubstr("<NetworkInterface name=\"eth1\"/>"));
  EXPECT_THAT(network, HasSubstr("<Peer address=\"robot.local\"/>"));
  EXPECT_THAT(ErrorOf([] {
                ParseTransport(json{{"domain", "seven"}});
              }),
              HasSubstr("transport.domain: expected an integer 0..232, got \"seven\""));
  EXPECT_THAT(ErrorOf([] {
                ParseTransport(json{{"namepsace", "/x"}});
              }),
              HasSubstr("transport: unknown key 'namepsace'"));
}

}  // namespace
}  // namespace saccade::dds
