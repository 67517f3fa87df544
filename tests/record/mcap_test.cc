// The MCAP writer and reader (record/mcap.h) against each other and against the specification's
// fixed points: messages read back byte for byte through zstd and uncompressed chunks, the
// summary's statistics, recovery of a recording cut short at random bytes (at most the open chunk
// lost), and clear errors for files that are not MCAP or are damaged. (Against the reference
// TypeScript implementation, @mcap/core: tests/record/mcap_reference.test.mjs.)
#include "saccade/record/mcap.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "record/internal_mcap_bytes.h"
#include "saccade/core/error.h"
#include "scratch_dir.h"

namespace saccade::record {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

fs::path TempFile(const std::string& name) { return testing_helpers::ScratchFile(name); }

struct Sent {
  uint16_t channel;
  uint64_t log_time, publish_time;
  std::vector<uint8_t> data;
};

// 600 messages on three channels every 10 ms, of 0 to 20,000 bytes (every 50th of 1.5 MB, an
// image's size), compressible and not.
std::vector<Sent> Messages(uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Sent> out;
  for (int i = 0; i < 600; ++i) {
    Sent m{static_cast<uint16_t>(1 + i % 3),
           uint64_t(i) * 10'000'000,
           uint64_t(i) * 10'000'000 - i,
           {}};
    const std::size_t size = i % 50 == 0 ? 1'500'000 : rng() % 20'000;
    m.data.resize(size);
    for (std::size_t k = 0; k < size; ++k) {
      m.data[k] = i % 2 ? static_cast<uint8_t>(rng()) : static_cast<uint8_t>(k / 64);
    }
    out.push_back(std::move(m));
  }
  return out;
}

void WriteAll(McapWriter& writer, const std::vector<Sent>& messages) {
  const uint16_t image = writer.AddSchema("sensor_msgs/msg/Image", "ros2msg", "uint32 height\n");
  const uint16_t joints =
      writer.AddSchema("sensor_msgs/msg/JointState", "ros2msg", "string[] name\n");
  EXPECT_EQ(writer.AddChannel(image, "/saccade/left/image_raw", "cdr"), 1);
  EXPECT_EQ(writer.AddChannel(image, "/saccade/right/image_raw", "cdr", {{"k", "v"}}), 2);
  EXPECT_EQ(writer.AddChannel(joints, "/saccade/joint_states", "cdr"), 3);
  for (const Sent& m : messages) writer.Write(m.channel, m.log_time, m.publish_time, m.data);
}

std::vector<Sent> ReadAll(const McapReader& reader) {
  std::vector<Sent> out;
  reader.ForEachMessage([&](const McapMessage& m) {
    out.push_back({m.channel_id, m.log_time, m.publish_time, {m.data.begin(), m.data.end()}});
    return true;
  });
  return out;
}

TEST(Mcap, Crc32IsTheIeeeCheckValue) {
  const std::string check = "123456789";
  EXPECT_EQ(internal::Crc32({reinterpret_cast<const uint8_t*>(check.data()), check.size()}),
            0xCBF43926u);
}

class McapRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(McapRoundTrip, MessagesComeBackByteForByteWithTheirSummary) {
  const fs::path file =
      TempFile("round_trip_" + (GetParam().empty() ? "none" : GetParam()) + ".mcap");
  const std::vector<Sent> sent = Messages(7);
  McapWriterOptions options;
  options.compression = GetParam();
  options.chunk_seconds = 0.5;
  {
    McapWriter writer(file, options);
    WriteAll(writer, sent);
    writer.Close();
    EXPECT_EQ(writer.bytes_written(), fs::file_size(file));
  }
  const McapReader reader(file);
  EXPECT_FALSE(reader.recovered());
  EXPECT_EQ(reader.profile(), "ros2");
  ASSERT_EQ(reader.schemas().size(), 2u);
  EXPECT_EQ(reader.schemas().at(1).name, "sensor_msgs/msg/Image");
  EXPECT_EQ(reader.schemas().at(2).data, "string[] name\n");
  ASSERT_EQ(reader.channels().size(), 3u);
  EXPECT_EQ(reader.channels().at(2).topic, "/saccade/right/image_raw");
  EXPECT_EQ(reader.channels().at(2).metadata.at("k"), "v");
  EXPECT_EQ(reader.channels().at(3).schema_id, 2);
  const McapStatistics& s = reader.statistics();
  EXPECT_EQ(s.message_count, sent.size());
  EXPECT_EQ(s.message_start_time, 0u);
  EXPECT_EQ(s.message_end_time, sent.back().log_time);
  EXPECT_EQ(s.channel_message_counts.at(1), 200u);
  // Chunks of at most 0.5 s of 6 s, and those over 4 MiB closed sooner.
  EXPECT_GE(s.chunk_count, 12u);
  const std::vector<Sent> got = ReadAll(reader);
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    ASSERT_EQ(got[i].channel, sent[i].channel) << i;
    ASSERT_EQ(got[i].log_time, sent[i].log_time) << i;
    ASSERT_EQ(got[i].publish_time, sent[i].publish_time) << i;
    ASSERT_EQ(got[i].data, sent[i].data) << i;
  }
  if (GetParam() == "zstd") {
    // The compressible half shrinks: the file is well under the raw bytes.
    std::size_t raw = 0;
    for (const Sent& m : sent) raw += m.data.size();
    EXPECT_LT(fs::file_size(file), raw * 3 / 4);
  }
}

INSTANTIATE_TEST_SUITE_P(Compression, McapRoundTrip, ::testing::Values("zstd", ""),
                         [](const auto& info) { return info.param.empty() ? "none" : "zstd"; });

// A recorder killed mid-run: the file stops anywhere. Every complete chunk is read back; what is
// lost is at most the open chunk (0.1 s: 10 messages), and what is read is exactly the first
// messages sent.
TEST(Mcap, ARecordingCutShortLosesAtMostItsOpenChunk) {
  const fs::path whole = TempFile("whole.mcap");
  const std::vector<Sent> sent = Messages(11);
  McapWriterOptions options;
  options.chunk_seconds = 0.1;
  {
    McapWriter writer(whole, options);
    WriteAll(writer, sent);
    writer.Close();
  }
  std::vector<char> bytes(fs::file_size(whole));
  std::ifstream(whole, std::ios::binary)
      .read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::mt19937 rng(3);
  for (int cut_index = 0; cut_index < 5; ++cut_index) {
    // Anywhere in the data section (the summary is the last ~10 %).
    const std::size_t cut = 100 + rng() % (bytes.size() * 9 / 10);
    SCOPED_TRACE("cut at byte " + std::to_string(cut) + " of " + std::to_string(bytes.size()));
    const fs::path file = TempFile("cut.mcap");
    std::ofstream(file, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(cut));
    const McapReader reader(file);
    EXPECT_TRUE(reader.recovered());
    EXPECT_GT(reader.lost_bytes(), 0u);
    const std::vector<Sent> got = ReadAll(reader);
    EXPECT_EQ(got.size(), reader.statistics().message_count);
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i].data, sent[i].data) << i;
    // What the cut chunk held is lost, no more: the next message's time is within the chunk's
    // 0.1 s of where it would have started (or 4 MiB of messages: an image chunk).
    ASSERT_LT(got.size(), sent.size());
    const uint64_t first_lost = sent[got.size()].log_time;
    uint64_t lost_before_cut = 0;
    for (std::size_t i = got.size(); i < sent.size(); ++i) {
      if (sent[i].log_time < first_lost + 100'000'000) ++lost_before_cut;
    }
    EXPECT_LE(lost_before_cut, 10u);
  }
  // A writer destroyed without Close (the process ended) leaves its chunks readable.
  const fs::path unclosed = TempFile("unclosed.mcap");
  {
    McapWriter writer(unclosed, options);
    WriteAll(writer, std::vector<Sent>(sent.begin(), sent.begin() + 100));
  }
  const McapReader reader(unclosed);
  EXPECT_TRUE(reader.recovered());
  EXPECT_EQ(reader.lost_bytes(), 0u);
  EXPECT_EQ(ReadAll(reader).size(), 100u);
}

// A recorder killed with SIGKILL (no destructor, no flush) at three random moments: the file
// keeps every chunk closed before the kill. A forked child writes the messages, telling the
// parent on a pipe each one it has written; the parent kills it after a random count.
TEST(Mcap, ARecorderKilledAtRandomMomentsLosesAtMostItsOpenChunk) {
  const std::vector<Sent> sent = Messages(23);
  std::mt19937 rng(std::random_device{}());
  const uint32_t seed = rng();
  SCOPED_TRACE("seed " + std::to_string(seed));
  rng.seed(seed);
  for (int kill_index = 0; kill_index < 3; ++kill_index) {
    const fs::path file = TempFile("killed.mcap");
    fs::remove(file);
    const std::size_t kill_after = 20 + rng() % (sent.size() - 40);
    SCOPED_TRACE("killed after message " + std::to_string(kill_after));
    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(pipe_fds[0]);
      McapWriterOptions options;
      options.chunk_seconds = 0.1;
      McapWriter writer(file, options);
      const uint16_t schema = writer.AddSchema("std_msgs/msg/String", "ros2msg", "string data\n");
      for (uint16_t c = 1; c <= 3; ++c) writer.AddChannel(schema, "/c" + std::to_string(c), "cdr");
      for (uint32_t i = 0; i < sent.size(); ++i) {
        writer.Write(sent[i].channel, sent[i].log_time, sent[i].publish_time, sent[i].data);
        if (::write(pipe_fds[1], &i, sizeof i) != sizeof i) ::_exit(2);
        ::usleep(500);
      }
      ::pause();  // until killed: the file is never closed
      ::_exit(0);
    }
    ::close(pipe_fds[1]);
    uint32_t written = 0;
    while (written < kill_after &&
           ::read(pipe_fds[0], &written, sizeof written) == sizeof written) {
    }
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    ::close(pipe_fds[0]);
    ASSERT_GE(written, kill_after);
    const McapReader reader(file);
    EXPECT_TRUE(reader.recovered());
    const std::vector<Sent> got = ReadAll(reader);
    ASSERT_LE(got.size(), sent.size());
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i].data, sent[i].data) << i;
    // Every message more than a chunk's 0.1 s older than the last one written is in the file.
    std::size_t must_have = 0;
    while (sent[must_have].log_time + 100'000'000 <= sent[written].log_time) ++must_have;
    EXPECT_GE(got.size(), must_have) << "written " << written;
  }
}

TEST(Mcap, FilesThatAreNotMcapOrAreDamagedAreNamed) {
  const auto error_of = [](const fs::path& file) -> std::string {
    try {
      const McapReader reader(file);
      ReadAll(reader);
    } catch (const FileError& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_THAT(error_of(TempFile("missing.mcap")), HasSubstr("no such recording"));
  const fs::path png = TempFile("picture.mcap");
  std::ofstream(png, std::ios::binary) << "\x89PNG\r\n\x1a\n0000000000000000";
  EXPECT_THAT(error_of(png), HasSubstr("not an MCAP file"));
  const fs::path empty = TempFile("empty.mcap");
  std::ofstream(empty, std::ios::binary).flush();
  EXPECT_THAT(error_of(empty), HasSubstr("not an MCAP file"));
  // A byte flipped inside a chunk: its CRC or its zstd frame says so, with the chunk's offset.
  for (const std::string compression : {"zstd", ""}) {
    const fs::path file = TempFile("damaged.mcap");
    McapWriterOptions options;
    options.compression = compression;
    {
      McapWriter writer(file, options);
      const std::vector<Sent> messages = Messages(5);
      WriteAll(writer, std::vector<Sent>(messages.begin(), messages.begin() + 20));
      writer.Close();
    }
    std::fstream io(file, std::ios::binary | std::ios::in | std::ios::out);
    io.seekp(400);
    io.put('\x5a');
    io.close();
    EXPECT_THAT(error_of(file), HasSubstr("byte ")) << compression;
    EXPECT_THAT(error_of(file), HasSubstr(file.string())) << compression;
  }
  EXPECT_THROW(McapWriter(TempFile("x.mcap"), McapWriterOptions{.compression = "lzma"}),
               InvalidArgument);
  EXPECT_THROW(McapWriter("/nonexistent-dir/x.mcap"), FileError);
}

}  // namespace
}  // namespace saccade::record
