// saccade's reader of ROS 2 messages by their definition (record/ros_message.h) against
// messages it did not write: Foxglove's CDR writer under Node, with the definitions of
// common_interfaces (tests/record/mcap_reference/ros2_sample.mjs). Every field comes back as
// written, whatever its type: signed and unsigned integers of each width, float32, float64,
// bool, strings, fixed and variable arrays, nested messages, byte arrays as spans.
#include "saccade/record/ros_message.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "record/run_node.h"
#include "saccade/core/error.h"

namespace saccade::record {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

struct Sample {
  std::vector<uint8_t> cdr;
  std::string definition;
};

// Foxglove's bytes and common_interfaces' definition of each input message.
std::vector<Sample> Reference(const json& inputs) {
  const fs::path input =
      fs::temp_directory_path() / ("saccade_ros_message_" + std::to_string(::getpid()) + ".json");
  std::ofstream(input) << inputs.dump();
  int status = 0;
  const std::string out = testing::RunNode("ros2_sample.mjs", "'" + input.string() + "'", &status);
  EXPECT_EQ(status, 0) << out;
  fs::remove(input);
  std::vector<Sample> samples;
  std::size_t start = 0;
  while (start < out.size()) {
    const std::size_t end = out.find('\n', start);
    const json line = json::parse(out.substr(start, end - start));
    Sample s;
    const std::string hex = line["hex"];
    for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
      s.cdr.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
    }
    s.definition = line["definition"];
    samples.push_back(std::move(s));
    start = end == std::string::npos ? out.size() : end + 1;
  }
  return samples;
}

TEST(RosMessageDecoder, ReadsWhatFoxglovesWriterWroteFieldForField) {
  const json imu = {
      {"header", {{"stamp", {{"sec", -3}, {"nanosec", 7}}}, {"frame_id", "imu"}}},
      {"orientation", {{"x", 0.5}, {"y", -0.25}, {"z", 0.125}, {"w", 1.0}}},
      {"orientation_covariance", {1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0}},
      {"angular_velocity", {{"x", 1e-300}, {"y", -2.5}, {"z", 3.0}}},
      {"angular_velocity_covariance", {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1}},
      {"linear_acceleration", {{"x", 9.81}, {"y", 0.0}, {"z", -1.0}}},
      {"linear_acceleration_covariance", {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0}}};
  // float32, uint8 beside constants, bool, variable float32 arrays, strings after them.
  const json battery = {
      {"header", {{"stamp", {{"sec", 12}, {"nanosec", 999999999}}}, {"frame_id", ""}}},
      {"voltage", 12.5},
      {"temperature", -4.25},
      {"current", 0.125},
      {"charge", 3.0},
      {"capacity", 4.0},
      {"design_capacity", 5.5},
      {"percentage", 0.75},
      {"power_supply_status", 2},
      {"power_supply_health", 7},
      {"power_supply_technology", 3},
      {"present", true},
      {"cell_voltage", {3.5, 3.25, 4.0}},
      {"cell_temperature", json::array()},
      {"location", "left arm"},
      {"serial_number", "SN-1"}};
  // Bytes in a nested message's array, after an odd-length string (unaligned).
  const json image = {{"header", {{"stamp", {{"sec", 1}, {"nanosec", 2}}}, {"frame_id", "cam"}}},
                      {"height", 2},
                      {"width", 3},
                      {"encoding", "mono8"},
                      {"is_bigendian", 0},
                      {"step", 3},
                      {"data", {{"bytes", {1, 2, 3, 250, 251, 252}}}}};
  // int64 at its extremes (exact: beyond a double's 2^53), uint32 at its largest.
  const json mixed = {
      {"layout",
       {{"dim", {{{"label", "rows"}, {"size", 4294967295u}, {"stride", 7}}}}, {"data_offset", 3}}},
      {"data", {{"bigints", {"-9223372036854775808", "9223372036854775807", "0", "-1"}}}}};
  const json inputs = {{{"type", "sensor_msgs/Imu"}, {"message", imu}},
                       {{"type", "sensor_msgs/BatteryState"}, {"message", battery}},
                       {{"type", "sensor_msgs/Image"}, {"message", image}},
                       {{"type", "std_msgs/Int64MultiArray"}, {"message", mixed}}};
  const std::vector<Sample> samples = Reference(inputs);
  ASSERT_EQ(samples.size(), 4u);
  const char* types[] = {"sensor_msgs/msg/Imu", "sensor_msgs/msg/BatteryState",
                         "sensor_msgs/msg/Image", "std_msgs/msg/Int64MultiArray"};
  for (std::size_t i = 0; i < samples.size(); ++i) {
    SCOPED_TRACE(types[i]);
    const RosMessageDecoder decoder(types[i], samples[i].definition);
    std::vector<std::span<const uint8_t>> blobs;
    json got = decoder.Decode(samples[i].cdr, &blobs);
    json expected = inputs[i]["message"];
    if (i == 3) {
      expected["data"] = {std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max(),
                          0, -1};
    }
    if (i == 2) {
      ASSERT_EQ(blobs.size(), 1u);
      EXPECT_EQ(got["data"], (json{{"blob", 0}}));
      EXPECT_EQ(std::vector<uint8_t>(blobs[0].begin(), blobs[0].end()),
                (std::vector<uint8_t>{1, 2, 3, 250, 251, 252}));
      got.erase("data");
      expected.erase("data");
    }
    EXPECT_EQ(got, expected) << got.dump() << "\n" << expected.dump();
  }
  // Cut short anywhere, the message is refused with the field and the byte.
  const RosMessageDecoder decoder(types[0], samples[0].definition);
  std::vector<std::span<const uint8_t>> blobs;
  for (std::size_t cut = 0; cut < samples[0].cdr.size(); cut += 7) {
    const std::span<const uint8_t> part(samples[0].cdr.data(), cut);
    EXPECT_THROW(decoder.Decode(part, &blobs), InvalidArgument) << cut;
  }
  try {
    decoder.Decode(std::span<const uint8_t>(samples[0].cdr.data(), 60), &blobs);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("sensor_msgs/Imu: orientation"));
    EXPECT_THAT(e.what(), HasSubstr("at byte"));
  }
}

TEST(RosMessageDecoder, DefinitionsThatDoNotDefineTheirTypesAreRefused) {
  try {
    RosMessageDecoder("my_msgs/msg/Thing", "my_msgs/Other other\nint32 x\n");
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("my_msgs/Other, which the definition does not define"));
  }
  EXPECT_THROW(RosMessageDecoder("a/msg/B", "int32[x] bad\n"), InvalidArgument);
  EXPECT_THROW(RosMessageDecoder("a/msg/B", "int32\n"), InvalidArgument);
}

}  // namespace
}  // namespace saccade::record
