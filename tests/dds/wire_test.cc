// saccade's messages on the ROS 2 wire, checked from outside: a plain Cyclone DDS program
// built from the tests' own IDL of the ROS 2 definitions (tests/dds/idl/, not saccade's
// headers) receives them, and their serialized bytes equal those of an independent ROS 2
// serializer (Foxglove's, under Node). Each test has its own DDS domain, on loopback.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "dds_test_util.h"
#include "saccade/components/messages.h"
#include "saccade/core/image.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/topics.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/geometry/pose.h"

namespace saccade::dds {
namespace {

using namespace saccade::dds::testing;
using components::JointCommand;
using components::JointStateMessage;
using components::MapMessage;
using components::TargetMessage;
using nlohmann::json;
using runtime::ImageMessage;

// A random image of `format` with a camera model and pose, as the renderer makes them.
std::shared_ptr<Image> MakeImage(int width, int height, PixelFormat format, uint32_t seed,
                                 const geometry::Distortion& distortion) {
  auto image = std::make_shared<Image>(width, height, format);
  std::mt19937 random(seed);
  for (std::size_t i = 0; i < image->size_bytes(); ++i) {
    image->data()[i] = static_cast<uint8_t>(random());
  }
  ImageMetadata& meta = image->metadata();
  meta.camera = "left";
  meta.time = 12.345678901;
  meta.frame_index = 308;
  geometry::SetCameraModel(
      meta, std::make_shared<const geometry::CameraModel>(
                geometry::Intrinsics(width, height, 812.5, 810.25, 0.5 * width + 3.25,
                                     0.5 * height - 1.5, 0.75),
                distortion));
  geometry::SetCameraPose(
      meta, geometry::MakePose(
                Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, -1.0, 0.4).normalized()).matrix(),
                Eigen::Vector3d(0.05, 0.1, 1.2)));
  return image;
}

geometry::Distortion RationalDistortion() {
  const double c[8] = {-0.21, 0.07, 0.001, -0.002, 0.01, 0.002, -0.003, 0.004};
  return geometry::Distortion::RadialTangential(c);
}

json Stamp(double seconds) {
  const auto ns = static_cast<int64_t>(std::llround(seconds * 1e9));
  return {{"sec", ns / 1000000000}, {"nanosec", ns % 1000000000}};
}

json Header(double seconds, const std::string& frame) {
  return {{"stamp", Stamp(seconds)}, {"frame_id", frame}};
}

// The ROS 2 message saccade's documented mapping (topics.h, docs/dds.md) makes of each.
json ExpectedImage(const Image& image) {
  const std::string base64 = Base64(image.data(), image.size_bytes());
  const char* encoding = image.format() == PixelFormat::kRgb8 ? "rgb8" : "mono8";
  return {{"header", Header(image.metadata().time, "left_optical")},
          {"height", image.height()},
          {"width", image.width()},
          {"encoding", encoding},
          {"is_bigendian", 0},
          {"step", image.stride()},
          {"data", {{"base64", base64}}}};
}

json ExpectedCameraInfo(const Image& image) {
  const geometry::CameraModel& model = *geometry::FindCameraModel(image.metadata());
  const geometry::Intrinsics& k = model.intrinsics();
  const std::vector<double>& c = model.distortion().coefficients();
  const bool rational = c[5] != 0 || c[6] != 0 || c[7] != 0;
  return {{"header", Header(image.metadata().time, "left_optical")},
          {"height", k.height()},
          {"width", k.width()},
          {"distortion_model", rational ? "rational_polynomial" : "plumb_bob"},
          {"d", std::vector<double>(c.begin(), c.begin() + (rational ? 8 : 5))},
          {"k", {k.fx(), k.skew(), k.cx(), 0.0, k.fy(), k.cy(), 0.0, 0.0, 1.0}},
          {"r", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}},
          {"p", {k.fx(), k.skew(), k.cx(), 0.0, 0.0, k.fy(), k.cy(), 0.0, 0.0, 0.0, 1.0, 0.0}},
          {"binning_x", 0},
          {"binning_y", 0},
          {"roi",
           {{"x_offset", 0}, {"y_offset", 0}, {"height", 0}, {"width", 0}, {"do_rectify", false}}}};
}

json ExpectedTf(const Image& image) {
  const geometry::Pose& X_WC = *geometry::FindCameraPose(image.metadata());
  const Eigen::Quaterniond q(X_WC.rotation());
  const Eigen::Vector3d t = X_WC.translation();
  return {{"transforms",
           {{{"header", Header(image.metadata().time, "world")},
             {"child_frame_id", "left_optical"},
             {"transform",
              {{"translation", {{"x", t.x()}, {"y", t.y()}, {"z", t.z()}}},
               {"rotation", {{"x", q.x()}, {"y", q.y()}, {"z", q.z()}, {"w", q.w()}}}}}}}}};
}

json ExpectedJoints(double time, const head::JointState& p, const head::JointState& v) {
  return {{"header", Header(time, "")},
          {"name", {"pan", "tilt", "left", "right"}},
          {"position", {p[0], p[1], p[2], p[3]}},
          {"velocity", {v[0], v[1], v[2], v[3]}},
          {"effort", json::array()}};
}

// Compares saccade's wire bytes with the reference's. CDR encapsulation: both say CDR_LE
// (00 01); Cyclone may pad the payload to 4 bytes and say so in the options' last two bits
// (XTypes 1.3, 7.4.3.5.2), so the payloads must agree up to the reference's length and the
// rest be that padding, zero.
void ExpectSameCdr(const std::vector<uint8_t>& ours, const std::string& reference_hex,
                   const std::string& what) {
  ASSERT_GE(ours.size(), 4u) << what << ": nothing received";
  ASSERT_GE(reference_hex.size(), 8u) << what;
  EXPECT_EQ(ours[0], 0x00) << what << ": encapsulation must be CDR_LE (XCDR1)";
  EXPECT_EQ(ours[1], 0x01) << what << ": encapsulation must be CDR_LE (XCDR1)";
  const std::string hex = Hex(ours);
  const std::size_t payload = reference_hex.size() - 8;
  ASSERT_GE(hex.size() - 8, payload) << what << ": saccade's bytes are shorter";
  EXPECT_EQ(hex.substr(8, payload), reference_hex.substr(8)) << what;
  const std::size_t padding = (hex.size() - 8 - payload) / 2;
  EXPECT_LT(padding, 4u) << what;
  EXPECT_EQ(static_cast<std::size_t>(ours[3] & 3), padding) << what << ": padding count";
  for (std::size_t i = ours.size() - padding; i < ours.size(); ++i) EXPECT_EQ(ours[i], 0) << what;
}

class WireTest : public ::testing::Test {
 protected:
  void SetUp() override { PinLoopback(); }
};

TEST_F(WireTest, PlainCycloneSubscriberDecodesTheImageBitExactly) {
  constexpr int kDomain = 161;
  auto participant = Participant::Create(Domain(kDomain));
  Raw raw(RawParticipant(kDomain));
  Raw reader(
      RawReader(raw.get(), &ref_sensor_msgs_msg_dds__Image__desc, "rt/saccade/left/image_raw"));
  auto writer =
      Writer::Create(participant, "runtime.image", Topic("/saccade/left/image_raw", Qos::Images()));
  ASSERT_TRUE(writer->WaitForReaders(1, 10));
  const auto image = MakeImage(1024, 768, PixelFormat::kRgb8, 7, RationalDistortion());
  writer->Write(ImageMessage{image});

  ref_sensor_msgs_msg_dds__Image_ got{};
  ASSERT_TRUE(TakeSample(reader.get(), &got));
  EXPECT_EQ(got.width, 1024u);
  EXPECT_EQ(got.height, 768u);
  EXPECT_EQ(got.step, 1024u * 3);
  EXPECT_STREQ(got.encoding, "rgb8");
  EXPECT_EQ(got.is_bigendian, 0);
  EXPECT_STREQ(got.header.frame_id, "left_optical");
  EXPECT_EQ(got.header.stamp.sec, 12);
  EXPECT_EQ(got.header.stamp.nanosec, 345678901u);
  ASSERT_EQ(got.data._length, image->size_bytes());
  EXPECT_EQ(std::memcmp(got.data._buffer, image->data(), image->size_bytes()), 0)
      << "the pixels differ";
  dds_sample_free(&got, &ref_sensor_msgs_msg_dds__Image__desc, DDS_FREE_CONTENTS);
}

// A raw Bayer mosaic (issue 45) is a sensor_msgs/Image with ROS's Bayer encoding, one sample a
// pixel: a plain Cyclone subscriber reads its encoding and bytes, and saccade's reader makes
// the same Bayer image of it again.
TEST_F(WireTest, BayerMosaicsTravelWithTheirRosEncodingBothWays) {
  constexpr int kDomain = 189;
  auto participant = Participant::Create(Domain(kDomain));
  Raw raw(RawParticipant(kDomain));
  const struct {
    PixelFormat format;
    const char* encoding;
    const char* topic;
  } cases[] = {{PixelFormat::kBayerGrbg8, "bayer_grbg8", "/saccade/left/image_raw"},
               {PixelFormat::kBayerRggb16, "bayer_rggb16", "/saccade/right/image_raw"}};
  for (const auto& c : cases) {
    Raw plain(
        RawReader(raw.get(), &ref_sensor_msgs_msg_dds__Image__desc, std::string("rt") + c.topic));
    auto reader = Reader::Create(participant, "runtime.image", Topic(c.topic, Qos::Images()));
    auto writer = Writer::Create(participant, "runtime.image", Topic(c.topic, Qos::Images()));
    ASSERT_TRUE(writer->WaitForReaders(2, 10)) << c.encoding;
    const auto image = MakeImage(37, 21, c.format, 11, RationalDistortion());
    writer->Write(ImageMessage{image});
    ref_sensor_msgs_msg_dds__Image_ got{};
    ASSERT_TRUE(TakeSample(plain.get(), &got)) << c.encoding;
    EXPECT_STREQ(got.encoding, c.encoding);
    EXPECT_EQ(got.step, 37u * BytesPerPixel(c.format));
    EXPECT_EQ(got.is_bigendian, 0);
    ASSERT_EQ(got.data._length, image->size_bytes());
    EXPECT_EQ(std::memcmp(got.data._buffer, image->data(), image->size_bytes()), 0);
    dds_sample_free(&got, &ref_sensor_msgs_msg_dds__Image__desc, DDS_FREE_CONTENTS);
    auto back = reader->Take<ImageMessage>(10.0);
    ASSERT_TRUE(back && back->image) << c.encoding;
    EXPECT_EQ(back->image->format(), c.format) << ToString(back->image->format());
    ASSERT_EQ(back->image->size_bytes(), image->size_bytes());
    EXPECT_EQ(std::memcmp(back->image->data(), image->data(), image->size_bytes()), 0);
  }
}

TEST_F(WireTest, TypeNamesAreRos2s) {
  // rmw_cyclonedds matches on these names (no XTypes type information: idlc -t).
  EXPECT_STREQ(ref_sensor_msgs_msg_dds__Image__desc.m_typename, "sensor_msgs::msg::dds_::Image_");
  constexpr int kDomain = 162;
  auto participant = Participant::Create(Domain(kDomain));
  Raw raw(RawParticipant(kDomain));
  // A reader of the right topic name and type name matches saccade's writer: the names agree.
  Raw reader(
      RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc, "rt/saccade/joint_states"));
  auto writer =
      Writer::Create(participant, "head.joints", Topic("/saccade/joint_states", Qos::Latched()));
  EXPECT_TRUE(WaitReaderMatched(reader.get()));
  EXPECT_EQ(RosTypeOf("head.joints"), "sensor_msgs/msg/JointState");
}

TEST_F(WireTest, BytesEqualAnIndependentRos2Serializer) {
  constexpr int kDomain = 163;
  auto participant = Participant::Create(Domain(kDomain));
  Raw raw(RawParticipant(kDomain));
  Raw image_reader(
      RawReader(raw.get(), &ref_sensor_msgs_msg_dds__Image__desc, "rt/cam/left/image"));
  Raw info_reader(
      RawReader(raw.get(), &ref_sensor_msgs_msg_dds__CameraInfo__desc, "rt/cam/left/camera_info"));
  Raw tf_reader(RawReader(raw.get(), &ref_tf2_msgs_msg_dds__TFMessage__desc, "rt/tf"));
  Raw joints_reader(
      RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc, "rt/saccade/joint_states"));
  Raw command_reader(
      RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc, "rt/saccade/head/command"));
  Raw target_reader(
      RawReader(raw.get(), &ref_geometry_msgs_msg_dds__PointStamped__desc, "rt/saccade/target"));
  auto images = Writer::Create(participant, "runtime.image", Topic("/cam/left/image"));
  auto joints = Writer::Create(participant, "head.joints", Topic("/saccade/joint_states"));
  auto commands = Writer::Create(participant, "head.command", Topic("/saccade/head/command"));
  auto targets = Writer::Create(participant, "vision.target", Topic("/saccade/target"));
  for (dds_entity_t r : {image_reader.get(), info_reader.get(), tf_reader.get(),
                         joints_reader.get(), command_reader.get(), target_reader.get()}) {
    ASSERT_TRUE(WaitReaderMatched(r));
  }

  // Odd sizes, so that strings and sequences leave the payload unaligned.
  const auto rgb = MakeImage(5, 3, PixelFormat::kRgb8, 1, RationalDistortion());
  const double plumb[5] = {-0.3, 0.12, 0.0005, -0.0007, 0.02};
  auto gray =
      MakeImage(7, 2, PixelFormat::kGray8, 2, geometry::Distortion::RadialTangential(plumb));
  gray->metadata().time = 0.04 * 3;
  JointStateMessage state;
  state.positions = state.velocities = state.targets = state.target_velocities =
      head::JointState::Popeye(0, 0, 0, 0);
  state.time = 7.04;
  state.positions = head::JointState::Popeye(0.1, -0.2, 0.3125, -0.0625);
  state.velocities = head::JointState::Popeye(1.5, 0, -2.25, 1e-9);
  JointCommand command;
  command.positions = command.velocities = head::JointState::Popeye(0, 0, 0, 0);
  command.time = 7.08;
  command.positions = head::JointState::Popeye(-0.4, 0.25, 0.05, -0.05);
  command.velocities = head::JointState::Popeye(0.0, 0.0, 0.0, 0.0);
  TargetMessage target;
  target.time = 7.12;
  target.valid = true;
  target.p_W = Eigen::Vector3d(1.25, -0.375, 1.6);

  json inputs = json::array();
  std::vector<std::vector<uint8_t>> ours;
  std::vector<std::string> what;
  for (const auto& image : {rgb, std::shared_ptr<Image>(gray)}) {
    images->Write(ImageMessage{image});
    ours.push_back(TakeCdr(tf_reader.get()));
    inputs.push_back({{"type", "tf2_msgs/TFMessage"}, {"message", ExpectedTf(*image)}});
    ours.push_back(TakeCdr(info_reader.get()));
    inputs.push_back({{"type", "sensor_msgs/CameraInfo"}, {"message", ExpectedCameraInfo(*image)}});
    ours.push_back(TakeCdr(image_reader.get()));
    inputs.push_back({{"type", "sensor_msgs/Image"}, {"message", ExpectedImage(*image)}});
    what.insert(what.end(), {"TFMessage", "CameraInfo", "Image"});
  }
  joints->Write(state);
  ours.push_back(TakeCdr(joints_reader.get()));
  inputs.push_back({{"type", "sensor_msgs/JointState"},
                    {"message", ExpectedJoints(state.time, state.positions, state.velocities)}});
  commands->Write(command);
  ours.push_back(TakeCdr(command_reader.get()));
  inputs.push_back(
      {{"type", "sensor_msgs/JointState"},
       {"message", ExpectedJoints(command.time, command.positions, command.velocities)}});
  targets->Write(target);
  ours.push_back(TakeCdr(target_reader.get()));
  inputs.push_back({{"type", "geometry_msgs/PointStamped"},
                    {"message",
                     {{"header", Header(target.time, "world")},
                      {"point", {{"x", 1.25}, {"y", -0.375}, {"z", 1.6}}}}}});
  what.insert(what.end(),
              {"JointState (head.joints)", "JointState (head.command)", "PointStamped"});

  const std::vector<std::string> reference = ReferenceSerialize(inputs);
  ASSERT_EQ(reference.size(), ours.size());
  for (std::size_t i = 0; i < ours.size(); ++i) ExpectSameCdr(ours[i], reference[i], what[i]);

  // The same messages serialized for a recording (Writer::CreateSerializing) are the same
  // bytes, in the same order, with their topics, ROS 2 types and stamps.
  std::vector<std::vector<uint8_t>> serialized;
  std::vector<std::string> topics, types;
  std::vector<int64_t> stamps;
  const SerializedSink sink = [&](const SerializedMessage& m) {
    serialized.emplace_back(m.data, m.data + m.size);
    topics.push_back(m.topic);
    types.push_back(m.ros_type);
    stamps.push_back(m.stamp_ns);
  };
  TopicOptions image_topic = Topic("/cam/left/image");
  image_topic.compressed_format = "";
  for (const auto& image : {rgb, std::shared_ptr<Image>(gray)}) {
    Writer::CreateSerializing("runtime.image", image_topic, sink)->Write(ImageMessage{image});
  }
  Writer::CreateSerializing("head.joints", Topic("/saccade/joint_states"), sink)->Write(state);
  Writer::CreateSerializing("head.command", Topic("/saccade/head/command"), sink)->Write(command);
  Writer::CreateSerializing("vision.target", Topic("/saccade/target"), sink)->Write(target);
  ASSERT_EQ(serialized.size(), ours.size());
  for (std::size_t i = 0; i < ours.size(); ++i) {
    ExpectSameCdr(serialized[i], reference[i], what[i] + " (serialized)");
  }
  EXPECT_EQ(topics, (std::vector<std::string>{"/tf", "/cam/left/camera_info", "/cam/left/image",
                                              "/tf", "/cam/left/camera_info", "/cam/left/image",
                                              "/saccade/joint_states", "/saccade/head/command",
                                              "/saccade/target"}));
  EXPECT_EQ(types[0], "tf2_msgs/msg/TFMessage");
  EXPECT_EQ(types[2], "sensor_msgs/msg/Image");
  EXPECT_EQ(types[8], "geometry_msgs/msg/PointStamped");
  EXPECT_EQ(stamps[5], 120'000'000);
  EXPECT_EQ(stamps[6], 7'040'000'000);
}

// A map of three voxels (z 0.75, 1.75 and 1.25: the bottom, the top and half way) and two
// inhibited places.
MapMessage ThreeVoxelMap(double time) {
  MapMessage map;
  map.time = time;
  map.resolution_m = 0.05;
  map.occupied_W = {{1.25, -0.5, 0.75}, {1.5, 0.25, 1.75}, {-2.0, 3.0, 1.25}};
  map.inhibited = {{{1.0, 0.5, 1.2}, 0.15, 1.0}, {{-0.5, 2.0, 0.8}, 0.3, 0.25}};
  map.fused = 4;
  return map;
}

// The PointCloud2 docs/dds.md says a map becomes: FLOAT32 fields packed little-endian in this
// order, `rgb` as PCL's 0x00RRGGBB (here blue, red and green by height), frame world, height 1.
json ExpectedCloud(double time, const std::vector<std::string>& names,
                   const std::vector<std::vector<double>>& points,
                   const std::vector<uint32_t>& rgb = {}) {
  const uint32_t step = 4 * static_cast<uint32_t>(names.size());
  std::vector<uint8_t> data;
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t f = 0; f < names.size(); ++f) {
      uint8_t bytes[4];
      if (names[f] == "rgb") {
        for (int b = 0; b < 4; ++b) bytes[b] = static_cast<uint8_t>(rgb[i] >> (8 * b));
      } else {
        const auto v = static_cast<float>(points[i][f]);
        std::memcpy(bytes, &v, 4);  // this machine is little-endian, as the cloud says
      }
      data.insert(data.end(), bytes, bytes + 4);
    }
  }
  json fields = json::array();
  for (std::size_t f = 0; f < names.size(); ++f) {
    fields.push_back({{"name", names[f]}, {"offset", 4 * f}, {"datatype", 7}, {"count", 1}});
  }
  return {{"header", Header(time, "world")},
          {"height", 1},
          {"width", points.size()},
          {"fields", fields},
          {"is_bigendian", false},
          {"point_step", step},
          {"row_step", step * points.size()},
          {"data", {{"base64", Base64(data)}}},
          {"is_dense", true}};
}

TEST_F(WireTest, MapCloudBytesEqualAnIndependentRos2Serializer) {
  constexpr int kDomain = 172;
  auto participant = Participant::Create(Domain(kDomain));
  Raw raw(RawParticipant(kDomain));
  Raw map_reader(
      RawReader(raw.get(), &ref_sensor_msgs_msg_dds__PointCloud2__desc, "rt/saccade/map"));
  Raw inhibited_reader(RawReader(raw.get(), &ref_sensor_msgs_msg_dds__PointCloud2__desc,
                                 "rt/saccade/map/inhibited"));
  TopicOptions options = Topic("/saccade/map");
  options.inhibited_topic = "/saccade/map/inhibited";
  auto writer = Writer::Create(participant, "mapping.map", options);
  ASSERT_TRUE(WaitReaderMatched(map_reader.get()));
  ASSERT_TRUE(WaitReaderMatched(inhibited_reader.get()));
  EXPECT_EQ(RosTypeOf("mapping.map"), "sensor_msgs/msg/PointCloud2");

  const MapMessage map = ThreeVoxelMap(7.04);
  writer->Write(map);
  const std::vector<std::vector<uint8_t>> ours = {TakeCdr(inhibited_reader.get()),
                                                  TakeCdr(map_reader.get())};
  const json inputs = {
      {{"type", "sensor_msgs/PointCloud2"},
       {"message", ExpectedCloud(7.04, {"x", "y", "z", "strength", "radius"},
                                 {{1.0, 0.5, 1.2, 1.0, 0.15}, {-0.5, 2.0, 0.8, 0.25, 0.3}})}},
      {{"type", "sensor_msgs/PointCloud2"},
       {"message", ExpectedCloud(7.04, {"x", "y", "z", "rgb"},
                                 {{1.25, -0.5, 0.75}, {1.5, 0.25, 1.75}, {-2.0, 3.0, 1.25}},
                                 {0x0000ff, 0xff0000, 0x00ff00})}}};
  const std::vector<std::string> reference = ReferenceSerialize(inputs);
  ASSERT_EQ(reference.size(), 2u);
  ExpectSameCdr(ours[0], reference[0], "PointCloud2 (inhibited)");
  ExpectSameCdr(ours[1], reference[1], "PointCloud2 (map)");

  // Serialized for a recording: the same bytes, the inhibited places first.
  std::vector<std::vector<uint8_t>> serialized;
  std::vector<std::string> topics, types;
  Writer::CreateSerializing("mapping.map", options, [&](const SerializedMessage& m) {
    serialized.emplace_back(m.data, m.data + m.size);
    topics.push_back(m.topic);
    types.push_back(m.ros_type);
    EXPECT_EQ(m.stamp_ns, 7'040'000'000);
  })->Write(map);
  ASSERT_EQ(serialized.size(), 2u);
  ExpectSameCdr(serialized[0], reference[0], "PointCloud2 (inhibited, serialized)");
  ExpectSameCdr(serialized[1], reference[1], "PointCloud2 (map, serialized)");
  EXPECT_EQ(topics, (std::vector<std::string>{"/saccade/map/inhibited", "/saccade/map"}));
  EXPECT_EQ(types, (std::vector<std::string>{"sensor_msgs/msg/PointCloud2",
                                             "sensor_msgs/msg/PointCloud2"}));
  const std::string definition = RosMessageDefinition("sensor_msgs/msg/PointCloud2");
  EXPECT_NE(definition.find("sensor_msgs/PointField[] fields\n"), std::string::npos);
  EXPECT_NE(definition.find("MSG: sensor_msgs/PointField\n"), std::string::npos);
}

// saccade to saccade: the Reader gives the map back from the two clouds, joined by stamp.
TEST_F(WireTest, MapRoundTripKeepsPointsAndInhibitedPlaces) {
  constexpr int kDomain = 173;
  auto participant = Participant::Create(Domain(kDomain));
  TopicOptions options = Topic("/saccade/map", Qos::Latched());
  options.inhibited_topic = "/saccade/map/inhibited";
  auto reader = Reader::Create(participant, "mapping.map", options);
  auto writer = Writer::Create(participant, "mapping.map", options);
  ASSERT_TRUE(writer->WaitForReaders(1, 10));
  // A map of many points (more than one UDP fragment) at odd coordinates.
  MapMessage map = ThreeVoxelMap(2.5);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-3.0, 3.0);
  for (int i = 0; i < 20000; ++i) {
    map.occupied_W.emplace_back(coordinate(random), coordinate(random), coordinate(random));
  }
  writer->Write(map);
  const auto got = reader->Take<MapMessage>(10.0);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->time, 2.5);
  ASSERT_EQ(got->occupied_W.size(), map.occupied_W.size());
  for (std::size_t i = 0; i < map.occupied_W.size(); ++i) {
    // The cloud's floats: each coordinate the float nearest the double.
    EXPECT_EQ(got->occupied_W[i], map.occupied_W[i].cast<float>().cast<double>()) << i;
  }
  ASSERT_EQ(got->inhibited.size(), 2u);
  EXPECT_EQ(got->inhibited[1].p_W, Eigen::Vector3d(-0.5, 2.0, static_cast<float>(0.8)));
  EXPECT_EQ(got->inhibited[1].strength, 0.25);
  EXPECT_EQ(got->inhibited[1].radius_m, static_cast<float>(0.3));
  EXPECT_EQ(got->resolution_m, 0.0) << "not in a PointCloud2";
  EXPECT_EQ(reader->stats().incomplete, 0);

  // A map without inhibited places sent (another publisher's cloud): none, counted incomplete.
  auto plain = Writer::Create(participant, "mapping.map", Topic("/saccade/map", Qos::Latched()));
  ASSERT_TRUE(plain->WaitForReaders(1, 10));
  plain->Write(ThreeVoxelMap(3.0));
  const auto bare = reader->Take<MapMessage>(10.0);
  ASSERT_TRUE(bare);
  EXPECT_EQ(bare->time, 3.0);
  EXPECT_EQ(bare->occupied_W.size(), 3u);
  EXPECT_TRUE(bare->inhibited.empty());
  EXPECT_EQ(reader->stats().incomplete, 1);
}

TEST(RosMessageDefinition, IsTheMsgFileWithItsDependenciesAsRosbag2StoresIt) {
  const std::string image = RosMessageDefinition("sensor_msgs/msg/Image");
  EXPECT_EQ(image.substr(0, image.find('=')),
            "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n"
            "uint8 is_bigendian\nuint32 step\nuint8[] data\n");
  EXPECT_NE(image.find(std::string(80, '=') + "\nMSG: std_msgs/Header\n"), std::string::npos);
  EXPECT_NE(image.find("MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"),
            std::string::npos);
  // Each type once, even when used twice (Vector3 and Quaternion through Transform).
  const std::string tf = RosMessageDefinition("tf2_msgs/msg/TFMessage");
  EXPECT_EQ(tf.find("MSG: std_msgs/Header"), tf.rfind("MSG: std_msgs/Header"));
  EXPECT_THROW(RosMessageDefinition("nav_msgs/msg/Odometry"), InvalidArgument);
}

TEST_F(WireTest, LateJoiningSubscriberGetsTheNewestJointState) {
  constexpr int kDomain = 164;
  auto participant = Participant::Create(Domain(kDomain));
  auto writer =
      Writer::Create(participant, "head.joints", Topic("/saccade/joint_states", Qos::Latched()));
  JointStateMessage state;
  state.positions = state.velocities = state.targets = state.target_velocities =
      head::JointState::Popeye(0, 0, 0, 0);
  for (int i = 1; i <= 3; ++i) {
    state.time = 0.04 * i;
    state.positions[0] = 0.1 * i;
    writer->Write(state);
  }
  // The subscriber joins after the three states: transient local gives it the newest.
  Raw raw(RawParticipant(kDomain));
  Raw reader(RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc,
                       "rt/saccade/joint_states", 10, /*transient_local=*/true));
  ref_sensor_msgs_msg_dds__JointState_ got{};
  ASSERT_TRUE(TakeSample(reader.get(), &got));
  ASSERT_EQ(got.position._length, 4u);
  EXPECT_EQ(got.position._buffer[0], 0.1 * 3);
  EXPECT_EQ(got.header.stamp.nanosec, 120000000u);
  dds_sample_free(&got, &ref_sensor_msgs_msg_dds__JointState__desc, DDS_FREE_CONTENTS);
  // Only the newest: the history is one deep.
  EXPECT_FALSE(TakeSample(reader.get(), &got, 0.3));
}

TEST_F(WireTest, ImageRoundTripKeepsPixelsModelAndPose) {
  constexpr int kDomain = 165;
  auto participant = Participant::Create(Domain(kDomain));
  auto reader = Reader::Create(participant, "runtime.image",
                               Topic("/saccade/left/image_raw", Qos::Images(), 0.04));
  auto writer = Writer::Create(participant, "runtime.image", Topic("/saccade/left/image_raw"));
  ASSERT_TRUE(writer->WaitForReaders(1, 10));
  const auto image = MakeImage(64, 48, PixelFormat::kRgb8, 3, RationalDistortion());
  writer->Write(ImageMessage{image});
  auto got = reader->Take<ImageMessage>(10.0);
  ASSERT_TRUE(got && got->image);
  const Image& out = *got->image;
  ASSERT_EQ(out.size_bytes(), image->size_bytes());
  EXPECT_EQ(std::memcmp(out.data(), image->data(), out.size_bytes()), 0);
  EXPECT_EQ(out.metadata().camera, "left");
  EXPECT_DOUBLE_EQ(out.metadata().time, 12.345678901);
  EXPECT_EQ(out.metadata().frame_index, 309);  // round(12.345678901 s / 0.04 s) = round(308.6)
  const geometry::CameraModel* model = geometry::FindCameraModel(out.metadata());
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(*model, *geometry::FindCameraModel(image->metadata()));  // doubles copied exactly
  const geometry::Pose* pose = geometry::FindCameraPose(out.metadata());
  ASSERT_NE(pose, nullptr);
  // Through a quaternion: equal to rounding.
  constexpr double kPoseTolerance = 1e-12;
  EXPECT_TRUE(pose->isApprox(*geometry::FindCameraPose(image->metadata()), kPoseTolerance));
  EXPECT_EQ(reader->stats().incomplete, 0);
  EXPECT_EQ(reader->stats().messages, 1);
}

// The reader converts only the newest of the images waiting (the older ones are counted lost),
// and reuses the memory of images nobody holds any more, never of one still held.
TEST_F(WireTest, ImageReaderKeepsTheNewestAndReusesOnlyReleasedFrames) {
  constexpr int kDomain = 167;
  const Qos keep_five{Reliability::kReliable, Durability::kVolatile, 5};
  auto participant = Participant::Create(Domain(kDomain));
  auto reader = Reader::Create(participant, "runtime.image",
                               Topic("/saccade/left/image_raw", keep_five, 0.04));
  auto writer =
      Writer::Create(participant, "runtime.image", Topic("/saccade/left/image_raw", keep_five));
  ASSERT_TRUE(writer->WaitForReaders(1, 10));
  ASSERT_TRUE(reader->WaitForWriters(1, 10));
  std::vector<std::shared_ptr<Image>> sent;
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    sent.push_back(MakeImage(64, 48, PixelFormat::kRgb8, seed, RationalDistortion()));
  }
  const auto Same = [](const Image& a, const Image& b) {
    return a.size_bytes() == b.size_bytes() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
  };
  // Three written before one take (a history of five keeps them all): the newest only.
  for (int i = 0; i < 3; ++i) writer->Write(ImageMessage{sent[i]});
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto first = reader->Take<ImageMessage>(10.0);
  ASSERT_TRUE(first && first->image);
  EXPECT_TRUE(Same(*first->image, *sent[2]));
  EXPECT_EQ(reader->stats().lost, 2);
  // Held: the next image is somewhere else, and the held one keeps its pixels.
  writer->Write(ImageMessage{sent[3]});
  auto second = reader->Take<ImageMessage>(10.0);
  ASSERT_TRUE(second && second->image);
  EXPECT_NE(second->image->data(), first->image->data());
  EXPECT_TRUE(Same(*second->image, *sent[3]));
  EXPECT_TRUE(Same(*first->image, *sent[2]));
  // Released: its memory comes back with a later image's pixels and metadata, and the image
  // still held is untouched.
  const uint8_t* released = first->image->data();
  first.reset();
  writer->Write(ImageMessage{sent[4]});
  auto third = reader->Take<ImageMessage>(10.0);
  ASSERT_TRUE(third && third->image);
  EXPECT_EQ(third->image->data(), released);
  EXPECT_TRUE(Same(*third->image, *sent[4]));
  EXPECT_TRUE(Same(*second->image, *sent[3]));
  EXPECT_NE(geometry::FindCameraModel(third->image->metadata()), nullptr);
  EXPECT_NE(geometry::FindCameraPose(third->image->metadata()), nullptr);
  EXPECT_EQ(reader->stats().lost, 2);
  EXPECT_EQ(reader->stats().incomplete, 0);
}

TEST_F(WireTest, ReaderCountsLateWaitsAndSkippedMessages) {
  constexpr int kDomain = 166;
  auto participant = Participant::Create(Domain(kDomain));
  auto reader =
      Reader::Create(participant, "head.command", Topic("/saccade/head/command", Qos::Default()));
  EXPECT_EQ(reader->Take<JointCommand>(0.05), nullptr);  // nobody writes: late, not blocked
  EXPECT_EQ(reader->stats().late, 1);
  auto writer = Writer::Create(participant, "head.command", Topic("/saccade/head/command"));
  ASSERT_TRUE(writer->WaitForReaders(1, 10));
  JointCommand command;
  command.positions = command.velocities = head::JointState::Popeye(0, 0, 0, 0);
  for (int i = 0; i < 3; ++i) {
    command.time = i;
    writer->Write(command);
  }
  ASSERT_TRUE(reader->WaitForWriters(1, 1));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  auto got = reader->Take<JointCommand>(1.0);
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(got->time, 2.0);           // the newest
  EXPECT_EQ(reader->stats().lost, 2);  // the two older ones, skipped
  command.time = 0.5;                  // the sender restarted
  writer->Write(command);
  ASSERT_NE(reader->Take<JointCommand>(1.0), nullptr);
  EXPECT_EQ(reader->stats().restarts, 1);
}

// A pipeline stepping on the sender's stamps (clock.source) asks for the message of its step's
// time: the newest stamped at or before it, with later ones kept for their own steps.
TEST_F(WireTest, ReaderHandsOverTheMessageOfTheAskedTimeAndKeepsLaterOnes) {
  constexpr int kDomain = 168;
  auto participant = Participant::Create(Domain(kDomain));
  auto reader = Reader::Create(participant, "head.joints",
                               Topic("/saccade/joint_states", Qos{Qos::Latched().reliability,
                                                                  Qos::Latched().durability, 64}));
  auto writer =
      Writer::Create(participant, "head.joints", Topic("/saccade/joint_states", Qos::Latched()));
  ASSERT_TRUE(writer->WaitForReaders(1, 10));
  // The sender runs ahead: four states before the receiver's first step.
  JointStateMessage state;
  state.positions = state.velocities = state.targets = state.target_velocities =
      head::JointState::Popeye(0, 0, 0, 0);
  for (const double t : {0.04, 0.08, 0.12, 0.16}) {
    state.time = t;
    state.positions[0] = t;
    writer->Write(state);
  }
  ASSERT_TRUE(reader->WaitForWriters(1, 5));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  auto first = reader->Take<JointStateMessage>(1.0, 0.08 + 0.5e-9);
  ASSERT_NE(first, nullptr);
  EXPECT_DOUBLE_EQ(first->time, 0.08);  // not the newest (0.16): the one of the step's time
  EXPECT_EQ(reader->stats().lost, 1);   // 0.04, before it
  // A step before every kept one gets nothing and does not wait for what is already there.
  EXPECT_EQ(reader->Take<JointStateMessage>(1.0, 0.1), nullptr);
  EXPECT_EQ(reader->stats().late, 0);
  auto second = reader->Take<JointStateMessage>(1.0, 0.12 + 0.5e-9);
  ASSERT_NE(second, nullptr);
  EXPECT_DOUBLE_EQ(second->time, 0.12);
  auto third = reader->Take<JointStateMessage>(1.0);  // no time asked: the newest
  ASSERT_NE(third, nullptr);
  EXPECT_DOUBLE_EQ(third->time, 0.16);
  EXPECT_EQ(reader->stats().lost, 1);
  EXPECT_EQ(reader->stats().messages, 3);
}

// The other eye's image of the step's time, not the newest: a stereo pair from one capture
// while the sender runs ahead. Images kept for later are converted only when handed over.
TEST_F(WireTest, ImageReaderHandsOverTheImageOfTheAskedTime) {
  constexpr int kDomain = 169;
  const Qos keep{Reliability::kReliable, Durability::kVolatile, 16};
  auto participant = Participant::Create(Domain(kDomain));
  auto reader =
      Reader::Create(participant, "runtime.image", Topic("/saccade/right/image_raw", keep, 0.04));
  auto writer =
      Writer::Create(participant, "runtime.image", Topic("/saccade/right/image_raw", keep));
  ASSERT_TRUE(writer->WaitForReaders(1, 10));
  ASSERT_TRUE(reader->WaitForWriters(1, 10));
  std::vector<std::shared_ptr<Image>> sent;
  for (uint32_t k = 1; k <= 4; ++k) {
    sent.push_back(MakeImage(64, 48, PixelFormat::kRgb8, k, RationalDistortion()));
    sent.back()->metadata().time = 0.04 * k;
    writer->Write(ImageMessage{sent.back()});
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto Same = [](const Image& a, const Image& b) {
    return a.size_bytes() == b.size_bytes() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
  };
  auto second = reader->Take<ImageMessage>(1.0, 0.08 + 0.5e-9);
  ASSERT_TRUE(second && second->image);
  EXPECT_TRUE(Same(*second->image, *sent[1]));
  EXPECT_EQ(second->image->metadata().frame_index, 2);
  EXPECT_EQ(reader->stats().lost, 1);                        // the first, before it
  EXPECT_EQ(reader->Take<ImageMessage>(1.0, 0.1), nullptr);  // kept ones are later: no wait
  EXPECT_EQ(reader->stats().late, 0);
  auto newest = reader->Take<ImageMessage>(1.0);
  ASSERT_TRUE(newest && newest->image);
  EXPECT_TRUE(Same(*newest->image, *sent[3]));
  EXPECT_NE(geometry::FindCameraPose(newest->image->metadata()), nullptr);
  EXPECT_EQ(reader->stats().lost, 2);
  EXPECT_EQ(reader->stats().messages, 2);
}

// Lockstep (TopicOptions::lockstep): a reader waits each step for the step's answer of every
// writer that announces lockstep, a command or an empty JointState marking the step; it never
// waits for other writers (a GUI's), and a mark is not a command.
TEST_F(WireTest, LockstepReaderWaitsForTheStepOfLockstepWritersOnly) {
  constexpr int kDomain = 170;
  auto robot = Participant::Create(Domain(kDomain));
  TopicOptions in = Topic("/saccade/head/command");
  in.lockstep = true;
  auto reader = Reader::Create(robot, "head.command", in);
  // A writer not in lockstep: it is never waited for.
  auto gui = Writer::Create(robot, "head.command", Topic("/saccade/head/command"));
  ASSERT_TRUE(gui->WaitForReaders(1, 10));
  EXPECT_EQ(reader->lockstep_writers(), 0);
  EXPECT_TRUE(reader->WaitForStep(0.0, 30.0));  // at once: nobody to wait for
  JointCommand command;
  command.positions = command.velocities = head::JointState::Popeye(0, 0, 0, 0);
  command.time = 5.0;
  command.positions[0] = 0.3;
  gui->Write(command);

  // Perception's writer, in its own participant, announces lockstep in its user data.
  auto perception = Participant::Create(Domain(kDomain));
  TopicOptions out = Topic("/saccade/head/command");
  out.lockstep = true;
  auto answer = Writer::Create(perception, "head.command", out);
  ASSERT_TRUE(reader->WaitForLockstepWriter(10));
  EXPECT_EQ(reader->lockstep_writers(), 1);
  // The GUI's command came meanwhile: handed over as ever.
  auto got = reader->Take<JointCommand>(1.0);
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(got->positions[0], 0.3);

  // A plain subscriber sees what the lockstep writer sends, as ROS 2 would.
  Raw raw(RawParticipant(kDomain));
  Raw wire(RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc,
                     "rt/saccade/head/command", 10));
  ASSERT_TRUE(WaitReaderMatched(wire.get()));
  ASSERT_TRUE(answer->WaitForReaders(2, 10));

  // Step 0.04: no answer yet, so the wait runs out and is counted late.
  EXPECT_FALSE(reader->WaitForStep(0.04, 0.3));
  EXPECT_EQ(reader->stats().late, 1);
  // Perception had no command for it: the step mark ends the wait, and is not a command.
  answer->MarkStep(0.04);
  EXPECT_TRUE(reader->WaitForStep(0.04, 30.0));
  EXPECT_EQ(reader->Take<JointCommand>(0.0), nullptr);
  EXPECT_EQ(reader->stats().lost, 0);
  // Step 0.08: the command is the answer; the mark adds nothing after it.
  command.time = 0.08;
  command.positions[0] = -0.2;
  answer->Write(command);
  answer->MarkStep(0.08);
  EXPECT_TRUE(reader->WaitForStep(0.08, 30.0));
  got = reader->Take<JointCommand>(0.0);
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(got->positions[0], -0.2);
  // An answer of an earlier step does not answer a later one (stamps are the steps' times).
  answer->MarkStep(0.08);
  EXPECT_FALSE(reader->WaitForStep(0.12, 0.3));

  // On the wire: the mark, an empty sensor_msgs/JointState stamped 0.04 s; then the command.
  ref_sensor_msgs_msg_dds__JointState_ sample{};
  ASSERT_TRUE(TakeSample(wire.get(), &sample));
  EXPECT_EQ(sample.name._length, 0u);
  EXPECT_EQ(sample.position._length, 0u);
  EXPECT_EQ(sample.header.stamp.sec, 0);
  EXPECT_EQ(sample.header.stamp.nanosec, 40000000u);
  dds_sample_free(&sample, &ref_sensor_msgs_msg_dds__JointState__desc, DDS_FREE_CONTENTS);
  sample = {};
  ASSERT_TRUE(TakeSample(wire.get(), &sample));
  EXPECT_EQ(sample.name._length, 4u);
  EXPECT_EQ(sample.header.stamp.nanosec, 80000000u);
  dds_sample_free(&sample, &ref_sensor_msgs_msg_dds__JointState__desc, DDS_FREE_CONTENTS);
  sample = {};
  ASSERT_TRUE(TakeSample(wire.get(), &sample));  // the second mark of 0.08: nothing came before it
  EXPECT_EQ(sample.name._length, 0u);
  dds_sample_free(&sample, &ref_sensor_msgs_msg_dds__JointState__desc, DDS_FREE_CONTENTS);

  // A lockstep writer that goes away ends the wait: a process that quit never stalls the loop.
  answer.reset();
  EXPECT_TRUE(reader->WaitForStep(0.16, 30.0));
  EXPECT_EQ(reader->lockstep_writers(), 0);
  // Only lockstep writers mark steps.
  EXPECT_THROW(gui->MarkStep(0.2), InvalidArgument);
}

// A joint state carries no targets: the writer sends them, of the same stamp, on a sibling
// topic, so the reader knows whether the head has arrived as the sender does, in smooth
// pursuit too (moving, on a moving target), which the velocities alone cannot tell.
TEST_F(WireTest, JointStatesBringTheirTargetsAndArrivalAsTheSenderSaysIt) {
  constexpr int kDomain = 171;
  auto participant = Participant::Create(Domain(kDomain));
  const Qos keep{Reliability::kReliable, Durability::kVolatile, 10};
  TopicOptions options = Topic("/saccade/joint_states", keep);
  options.targets_topic = "/saccade/joint_targets";
  auto writer = Writer::Create(participant, "head.joints", options);
  auto reader = Reader::Create(participant, "head.joints", options);
  // One that does not ask for the targets: the old rule, at rest on its positions.
  auto plain = Reader::Create(participant, "head.joints", Topic("/saccade/joint_states", keep));
  Raw raw(RawParticipant(kDomain));
  Raw wire(RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc,
                     "rt/saccade/joint_targets", 10));
  ASSERT_TRUE(WaitReaderMatched(wire.get()));
  ASSERT_TRUE(writer->WaitForReaders(2, 10));
  ASSERT_TRUE(reader->WaitForWriters(1, 10));

  // Pursuit, on its target: sim.head says arrived while every joint moves at 0.02 rad/s.
  JointStateMessage pursuit;
  pursuit.positions = pursuit.velocities = pursuit.targets = pursuit.target_velocities =
      head::JointState::Popeye(0, 0, 0, 0);
  pursuit.time = 0.04;
  pursuit.positions = head::JointState::Popeye(0.2, -0.1, 0.05, -0.05);
  pursuit.velocities = head::JointState::Popeye(0.02, 0.0, 0.01, -0.01);
  pursuit.targets = head::JointState::Popeye(0.20005, -0.1, 0.05, -0.05);
  pursuit.target_velocities = head::JointState::Popeye(0.02, 0.0, 0.01, -0.01);
  pursuit.arrived = true;
  writer->Write(pursuit);
  auto got = reader->Take<JointStateMessage>(5.0);
  ASSERT_NE(got, nullptr);
  EXPECT_TRUE(got->arrived);
  EXPECT_EQ(got->targets[0], 0.20005);
  EXPECT_EQ(got->target_velocities[0], 0.02);
  auto old = plain->Take<JointStateMessage>(5.0);
  ASSERT_NE(old, nullptr);
  EXPECT_FALSE(old->arrived);               // moving: what the velocities alone say
  EXPECT_EQ(plain->stats().incomplete, 0);  // it asked for no targets

  // On the way to a target 0.1 rad off, at rest for an instant: not arrived.
  JointStateMessage turning = pursuit;
  turning.time = 0.08;
  turning.velocities = {};
  turning.targets[0] = 0.3;
  turning.target_velocities = {};
  turning.arrived = false;
  writer->Write(turning);
  got = reader->Take<JointStateMessage>(5.0);
  ASSERT_NE(got, nullptr);
  EXPECT_FALSE(got->arrived);
  EXPECT_EQ(got->targets[0], 0.3);
  old = plain->Take<JointStateMessage>(5.0);
  ASSERT_NE(old, nullptr);
  EXPECT_TRUE(old->arrived);  // at rest: the velocities alone are wrong again

  // A servo head settled within its own tolerance (3 mrad off its goal) says arrived: the
  // target sent is where it is, so the reader says so too.
  JointStateMessage servo = turning;
  servo.time = 0.12;
  servo.targets[0] = servo.positions[0] + 0.003;
  servo.arrived = true;
  writer->Write(servo);
  got = reader->Take<JointStateMessage>(5.0);
  ASSERT_NE(got, nullptr);
  EXPECT_TRUE(got->arrived);
  EXPECT_EQ(reader->stats().incomplete, 0);

  // On the wire: ROS 2 JointStates of the four joints, stamped as their states.
  ref_sensor_msgs_msg_dds__JointState_ sample{};
  ASSERT_TRUE(TakeSample(wire.get(), &sample));
  ASSERT_EQ(sample.name._length, 4u);
  EXPECT_STREQ(sample.name._buffer[0], "pan");
  EXPECT_EQ(sample.position._buffer[0], 0.20005);
  EXPECT_EQ(sample.velocity._buffer[0], 0.02);
  EXPECT_EQ(sample.header.stamp.nanosec, 40000000u);
  dds_sample_free(&sample, &ref_sensor_msgs_msg_dds__JointState__desc, DDS_FREE_CONTENTS);
}

}  // namespace
}  // namespace saccade::dds
