// Recordings in MCAP from the command line (issue 43): `--record FILE.mcap`, `saccade mcap
// info`, a recording killed with SIGKILL, and `saccade run --play` of a recording in lockstep,
// which computes what the live run computed, bit for bit.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "e2e/run_saccade.h"
#include "saccade/core/error.h"
#include "saccade/record/mcap.h"
#include "saccade/record/ros_message.h"

namespace saccade::e2e {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

const std::string kBinary = SACCADE_BINARY;
const std::string kSource = SACCADE_SOURCE_DIR;
const std::string kPipelines = kSource + "/pipelines/";

class RecordCli : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("CYCLONEDDS_URI", "file://" SACCADE_SOURCE_DIR "/config/dds/loopback.xml", 0);
    dir_ = fs::temp_directory_path() /
           ("saccade-record-e2e-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// Every message's bytes, by topic, in the order recorded.
std::map<std::string, std::vector<std::vector<uint8_t>>> MessagesByTopic(const std::string& file) {
  const record::McapReader reader(file);
  std::map<std::string, std::vector<std::vector<uint8_t>>> out;
  reader.ForEachMessage([&](const record::McapMessage& m) {
    out[reader.channels().at(m.channel_id).topic].emplace_back(m.data.begin(), m.data.end());
    return true;
  });
  return out;
}

// The split demo (robot and perception over DDS, in lockstep) is the live run; the robot's
// recording played back into perception in lockstep gives every output perception computed
// live, byte for byte: detections, stereo candidates, selections, tracks, targets, commands.
TEST_F(RecordCli, ReplayInLockstepComputesWhatTheLiveRunDidBitForBit) {
  constexpr int kSteps = 30;
  const std::string steps = " --steps " + std::to_string(kSteps);
  BackgroundProcess perception({kBinary, "run", kPipelines + "perception.yaml", "--dds-domain",
                                "214", "--steps", std::to_string(kSteps), "--record",
                                Path("live.mcap")});
  const CommandRun robot = Saccade("run " + kPipelines + "robot.yaml --dds-domain 214" + steps +
                                   " --record " + Path("robot.mcap"));
  ASSERT_EQ(robot.status, 0) << robot.output;
  std::string perception_output;
  while (const auto line = perception.ReadLine(std::chrono::seconds(120))) {
    perception_output += *line;
  }
  const CommandRun replay =
      Saccade("run " + kPipelines + "perception.yaml --dds-domain 215 --play " +
              Path("robot.mcap") + " --record " + Path("replay.mcap"));
  ASSERT_EQ(replay.status, 0) << replay.output;
  EXPECT_THAT(replay.output, HasSubstr("play: " + std::to_string(kSteps) + " steps"));
  EXPECT_THAT(replay.output, ::testing::Not(HasSubstr("answered late")));

  const auto live = MessagesByTopic(Path("live.mcap"));
  const auto replayed = MessagesByTopic(Path("replay.mcap"));
  for (const char* topic :
       {"/saccade/faces_left/faces", "/saccade/faces_right/faces", "/saccade/stereo/candidates",
        "/saccade/attention/selection", "/saccade/track_left/track", "/saccade/track_right/track",
        "/saccade/triangulate/target", "/saccade/fixation/command"}) {
    SCOPED_TRACE(topic);
    ASSERT_TRUE(live.count(topic)) << perception_output;
    ASSERT_TRUE(replayed.count(topic)) << replay.output;
    const auto& a = live.at(topic);
    const auto& b = replayed.at(topic);
    EXPECT_GE(a.size(), static_cast<std::size_t>(kSteps) - 6);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "message " << i;
  }
}

// A demo recording holds every topic (images, camera info, joint states and targets, the URDF,
// TF, detections, targets, ground truth) with the run's head; `mcap info` says so. An existing
// recording is kept unless --force.
TEST_F(RecordCli, TheDemoRecordsEveryTopicOfAnyHeadAndMcapInfoDescribesIt) {
  const std::string file = Path("humanoid.mcap");
  const CommandRun demo =
      Saccade("demo --duration 0.4 --head " + kSource + "/robots/humanoid.yaml --record " + file);
  ASSERT_EQ(demo.status == 0 || demo.status == 3, true) << demo.output;
  EXPECT_THAT(demo.output, HasSubstr("record: 10 steps"));
  const CommandRun info = Saccade("mcap info --json " + file);
  ASSERT_EQ(info.status, 0) << info.output;
  const json report = json::parse(info.output);
  EXPECT_EQ(report["complete"], true);
  EXPECT_EQ(report["metadata"]["saccade"]["head"], "humanoid");
  EXPECT_EQ(report["metadata"]["saccade"]["command"], "demo");
  std::map<std::string, std::pair<std::string, int>> channels;
  for (const json& c : report["channels"]) {
    channels[c["topic"]] = {c["type"], c["messages"].get<int>()};
  }
  EXPECT_EQ(channels["/saccade/left/image_raw"],
            std::make_pair(std::string("sensor_msgs/msg/Image"), 10));
  EXPECT_EQ(channels["/saccade/right/camera_info"].first, "sensor_msgs/msg/CameraInfo");
  EXPECT_EQ(channels["/saccade/joint_states"].first, "sensor_msgs/msg/JointState");
  EXPECT_EQ(channels["/saccade/joint_targets"].second, 10);
  EXPECT_EQ(channels["/saccade/robot_description"].second, 1);
  EXPECT_EQ(channels["/tf"].first, "tf2_msgs/msg/TFMessage");
  EXPECT_EQ(channels["/saccade/faces_left/faces"].first, "json");
  EXPECT_EQ(channels["/saccade/ground_truth"].second, 10);
  EXPECT_NEAR(report["duration_s"].get<double>(), 0.36, 1e-9);
  const CommandRun text = Saccade("mcap info " + file);
  EXPECT_THAT(text.output, HasSubstr("saccade.head: humanoid"));
  EXPECT_THAT(text.output, ::testing::ContainsRegex(
                               "/saccade/left/image_raw +sensor_msgs/msg/Image +10 +25.00"));

  // Exported to a data set folder: a line per frame, each camera's PNG the recorded pixels.
  const CommandRun exported = Saccade("mcap export " + file + " --out " + Path("set"));
  ASSERT_EQ(exported.status, 0) << exported.output;
  EXPECT_THAT(exported.output, HasSubstr("10 frames"));
  std::ifstream index(Path("set/frames.jsonl"));
  std::vector<json> frames;
  for (std::string line; std::getline(index, line);) frames.push_back(json::parse(line));
  ASSERT_EQ(frames.size(), 10u);
  EXPECT_EQ(frames[3]["frame"], 3);
  EXPECT_NEAR(frames[3]["time"].get<double>(), 0.12, 1e-12);
  EXPECT_EQ(frames[3]["cameras"]["left"]["file"], "left/000003.png");
  EXPECT_NEAR(frames[3]["cameras"]["right"]["K"][0][0].get<double>(), 1210.99, 0.01);
  EXPECT_EQ(frames[3]["cameras"]["left"]["X_WC"].size(), 4u);
  EXPECT_TRUE(frames[3]["cameras"]["left"]["joints"].contains("neck_yaw"))
      << frames[3]["cameras"]["left"].dump();
  {
    const record::McapReader reader(file);
    int left = 0;
    bool compared = false;
    reader.ForEachMessage([&](const record::McapMessage& m) {
      const auto& channel = reader.channels().at(m.channel_id);
      if (channel.topic != "/saccade/left/image_raw" || left++ != 3) return true;
      const auto& schema = reader.schemas().at(channel.schema_id);
      const record::RosMessageDecoder decoder(schema.name, schema.data);
      std::vector<std::span<const uint8_t>> blobs;
      const json image = decoder.Decode(m.data, &blobs);
      cv::Mat bgr = cv::imread(Path("set/left/000003.png"), cv::IMREAD_UNCHANGED);
      EXPECT_EQ(bgr.cols, image["width"].get<int>());
      if (bgr.empty()) return false;
      cv::Mat rgb;
      cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
      EXPECT_EQ(0, std::memcmp(rgb.data, blobs[0].data(), blobs[0].size()));
      compared = true;
      return false;
    });
    EXPECT_TRUE(compared);
  }

  // Not replaced without --force; nothing else is refused silently.
  const auto size = fs::file_size(file);
  const CommandRun again = Saccade("demo --duration 0.4 --record " + file);
  EXPECT_EQ(again.status, 1);
  EXPECT_THAT(again.output, HasSubstr("the file exists; --force replaces it"));
  EXPECT_EQ(fs::file_size(file), size);
  const CommandRun bad =
      Saccade("run " + kPipelines + "demo.yaml --steps 1 --record " + Path("x.mp4"));
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("an MCAP recording's name ends in .mcap"));
}

// SIGKILL at three random moments of a recording: the file keeps its complete chunks, which
// `mcap info` reads (saying it was cut short) and --play plays.
TEST_F(RecordCli, ARecordingKilledAtRandomMomentsKeepsItsCompleteChunks) {
  std::mt19937 rng(std::random_device{}());
  for (int kill_index = 0; kill_index < 3; ++kill_index) {
    const std::string file = Path("killed" + std::to_string(kill_index) + ".mcap");
    const int after_ms = 1500 + static_cast<int>(rng() % 4000);
    SCOPED_TRACE("killed after " + std::to_string(after_ms) + " ms");
    BackgroundProcess run({kBinary, "run", kPipelines + "demo.yaml", "--steps", "0", "--record",
                           file, "--record-chunk-s", "0.2"});
    std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
    ::kill(run.pid(), SIGKILL);
    run.Stop();
    const record::McapReader reader(file);
    EXPECT_TRUE(reader.recovered());
    // Each topic's messages come back without a gap: sequences 0, 1, 2, ...
    std::map<uint16_t, uint32_t> next;
    reader.ForEachMessage([&](const record::McapMessage& m) {
      EXPECT_EQ(m.sequence, next[m.channel_id]++) << reader.channels().at(m.channel_id).topic;
      return true;
    });
    const CommandRun info = Saccade("mcap info " + file);
    EXPECT_EQ(info.status, 0) << info.output;
    EXPECT_THAT(info.output,
                HasSubstr("cut short (no summary): the complete chunks were recovered"));
  }
}

TEST_F(RecordCli, FilesThatAreNotRecordingsGetAClearError) {
  std::ofstream(Path("text.mcap")) << "not a recording\n";
  const CommandRun info = Saccade("mcap info " + Path("text.mcap"));
  EXPECT_EQ(info.status, 1);
  EXPECT_THAT(info.output, HasSubstr("text.mcap"));
  EXPECT_THAT(info.output, HasSubstr("not an MCAP file"));
  const CommandRun play =
      Saccade("run " + kPipelines + "perception.yaml --dds-domain 216 --play " + Path("text.mcap"));
  EXPECT_EQ(play.status, 1);
  EXPECT_THAT(play.output, HasSubstr("not an MCAP file"));
  const CommandRun missing = Saccade("mcap info " + Path("none.mcap"));
  EXPECT_EQ(missing.status, 1);
  EXPECT_THAT(missing.output, HasSubstr("none.mcap"));
}

}  // namespace
}  // namespace saccade::e2e
