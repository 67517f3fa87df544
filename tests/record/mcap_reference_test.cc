// saccade's MCAP files against the reference implementation, Foxglove's @mcap/core under Node
// (tests/record/mcap_reference/, `npm ci` by the setup): a file saccade wrote is read by
// @mcap/core's stream reader with every CRC checked and by its indexed reader through the
// summary, chunk and message indexes, and gives back every message as written; a file
// @mcap/core wrote is read by saccade's reader.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "record/run_node.h"
#include "saccade/record/mcap.h"
#include "scratch_dir.h"

namespace saccade::record {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path TempFile(const std::string& name) { return testing_helpers::ScratchFile(name); }

// The reference script on `file`; its output, and its exit status in `*status`.
std::string Node(const std::string& command, const fs::path& file, int* status) {
  return testing::RunNode("mcap_reference.mjs", command + " '" + file.string() + "'", status);
}

uint32_t Fnv1a(std::span<const uint8_t> bytes) {
  uint32_t h = 0x811c9dc5u;
  for (const uint8_t b : bytes) h = (h ^ b) * 0x01000193u;
  return h;
}

class McapReference : public ::testing::TestWithParam<std::string> {};

TEST_P(McapReference, ReadsWhatSaccadeWroteMessageForMessage) {
  const fs::path file = TempFile("saccade_" + (GetParam().empty() ? "none" : GetParam()) + ".mcap");
  struct Sent {
    uint16_t channel;
    uint32_t sequence;
    uint64_t log_time, publish_time;
    std::size_t size;
    uint32_t hash;
  };
  std::vector<Sent> sent;
  McapWriterOptions options;
  options.compression = GetParam();
  options.chunk_seconds = 0.25;
  uint32_t chunks = 0;
  {
    McapWriter writer(file, options);
    const uint16_t image = writer.AddSchema("sensor_msgs/msg/Image", "ros2msg", "uint32 height\n");
    const uint16_t text = writer.AddSchema("std_msgs/msg/String", "ros2msg", "string data\n");
    const uint16_t left = writer.AddChannel(image, "/saccade/left/image_raw", "cdr", {{"a", "b"}});
    const uint16_t words = writer.AddChannel(text, "/saccade/robot_description", "cdr");
    std::mt19937 rng(17);
    std::array<uint32_t, 3> sequences{};
    for (int i = 0; i < 200; ++i) {
      const uint16_t channel = i % 4 == 0 ? words : left;
      std::vector<uint8_t> data(i % 40 == 0 ? 1'000'000 : rng() % 30'000);
      for (auto& b : data) b = static_cast<uint8_t>(i % 3 == 0 ? rng() : i);
      const uint64_t t = uint64_t(i) * 40'000'000;
      writer.Write(channel, t, t - 1'000, data);
      sent.push_back({channel, sequences[channel]++, t, t - 1'000, data.size(), Fnv1a(data)});
    }
    writer.Close();
    chunks = writer.statistics().chunk_count;
  }
  int status = 0;
  const std::string out = Node("read", file, &status);
  ASSERT_EQ(status, 0) << out;
  const json r = json::parse(out);
  EXPECT_EQ(r["header"]["profile"], "ros2");
  EXPECT_EQ(r["header"]["library"], "saccade");
  ASSERT_EQ(r["schemas"].size(), 2u);
  EXPECT_EQ(r["schemas"][1]["name"], "std_msgs/msg/String");
  EXPECT_EQ(r["schemas"][1]["encoding"], "ros2msg");
  EXPECT_EQ(r["schemas"][1]["data"], "string data\n");
  ASSERT_EQ(r["channels"].size(), 2u);
  EXPECT_EQ(r["channels"][0]["topic"], "/saccade/left/image_raw");
  EXPECT_EQ(r["channels"][0]["metadata"]["a"], "b");
  EXPECT_EQ(r["channels"][1]["schema_id"], 2);
  EXPECT_EQ(r["statistics"]["message_count"], "200");
  EXPECT_EQ(r["statistics"]["chunk_count"], chunks);
  EXPECT_EQ(r["statistics"]["channel_message_counts"]["2"], "50");
  EXPECT_EQ(r["statistics"]["message_end_time"], std::to_string(199ull * 40'000'000));
  EXPECT_EQ(r["chunk_indexes"], chunks);
  EXPECT_GT(chunks, 20u);  // 0.25 s chunks of 8 s
  EXPECT_NE(r["data_section_crc"], nullptr);
  // One message index per channel in each chunk: both channels write every 0.25 s chunk.
  EXPECT_EQ(r["records"]["MessageIndex"], 2 * chunks);
  EXPECT_EQ(r["records"]["ChunkIndex"], chunks);
  EXPECT_EQ(r["records"]["Statistics"], 1);
  EXPECT_EQ(r["records"]["DataEnd"], 1);
  EXPECT_EQ(r["records"]["Message"], 200);
  EXPECT_EQ(r["records"]["Footer"], 1);
  const json& got = r["messages"];
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(got[i]["channel"], sent[i].channel);
    EXPECT_EQ(got[i]["sequence"], sent[i].sequence);
    EXPECT_EQ(got[i]["log_time"], std::to_string(sent[i].log_time));
    EXPECT_EQ(got[i]["publish_time"], std::to_string(sent[i].publish_time));
    EXPECT_EQ(got[i]["size"], sent[i].size);
    EXPECT_EQ(got[i]["fnv1a"], sent[i].hash);
  }
}

INSTANTIATE_TEST_SUITE_P(Compression, McapReference, ::testing::Values("zstd", ""),
                         [](const auto& info) { return info.param.empty() ? "none" : "zstd"; });

TEST(McapReference, SaccadeReadsWhatMcapCoreWrote) {
  const fs::path file = TempFile("mcap_core.mcap");
  int status = 0;
  const std::string out = Node("write", file, &status);
  ASSERT_EQ(status, 0) << out;
  const McapReader reader(file);
  EXPECT_FALSE(reader.recovered());
  EXPECT_EQ(reader.library(), "@mcap/core");
  ASSERT_EQ(reader.channels().size(), 2u);
  EXPECT_EQ(reader.channels().begin()->second.topic, "/a");
  EXPECT_EQ(reader.channels().begin()->second.metadata.at("from"), "node");
  EXPECT_EQ(reader.schemas().begin()->second.data, "string data\n");
  EXPECT_EQ(reader.statistics().message_count, 300u);
  int i = 0;
  reader.ForEachMessage([&](const McapMessage& m) {
    EXPECT_EQ(m.sequence, static_cast<uint32_t>(i));
    EXPECT_EQ(m.log_time, uint64_t(i) * 20'000'000);
    EXPECT_EQ(m.publish_time, uint64_t(i) * 20'000'000 + 5);
    EXPECT_EQ(m.data.size(), static_cast<std::size_t>((i * 37) % 5000 + 1));
    bool same = true;
    for (const uint8_t b : m.data) same = same && b == i % 251;
    EXPECT_TRUE(same) << i;
    ++i;
    return true;
  });
  EXPECT_EQ(i, 300);
}

}  // namespace
}  // namespace saccade::record
