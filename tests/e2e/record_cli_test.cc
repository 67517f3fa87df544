// Recordings in MCAP from the command line (issue 43): `--record FILE.mcap`, `saccade mcap
// info`, a recording killed with SIGKILL, and `saccade run --play` of a recording in lockstep,
// which computes what the live run computed, bit for bit.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
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
    // A parametrized test's name holds a '/' ("Replay.../popeye"): one folder, not two.
    std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::replace(name.begin(), name.end(), '/', '_');
    dir_ = fs::temp_directory_path() /
           ("saccade-record-e2e-" + std::to_string(::getpid()) + "-" + name);
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
// With POPEYE (the scene's head) and with the six-joint humanoid head (--head on both).
struct ReplayCase {
  const char* name;
  std::string head;  // "" : the scene's
  const char* live_domain;
  const char* replay_domain;
};

class ReplayCli : public RecordCli, public ::testing::WithParamInterface<ReplayCase> {};

TEST_P(ReplayCli, ReplayInLockstepComputesWhatTheLiveRunDidBitForBit) {
  constexpr int kSteps = 30;
  const std::string steps = " --steps " + std::to_string(kSteps);
  const std::string head = GetParam().head.empty() ? "" : " --head " + GetParam().head;
  const std::string live_domain = GetParam().live_domain;
  std::vector<std::string> perception_args = {
      kBinary,          "run",     kPipelines + "perception.yaml", "--dds-domain",
      live_domain,      "--steps", std::to_string(kSteps),         "--record",
      Path("live.mcap")};
  if (!GetParam().head.empty()) {
    perception_args.insert(perception_args.end(), {"--head", GetParam().head});
  }
  BackgroundProcess perception(perception_args);
  const CommandRun robot = Saccade("run " + kPipelines + "robot.yaml --dds-domain " + live_domain +
                                   steps + head + " --record " + Path("robot.mcap"));
  ASSERT_EQ(robot.status, 0) << robot.output;
  std::string perception_output;
  while (const auto line = perception.ReadLine(std::chrono::seconds(120))) {
    perception_output += *line;
  }
  const CommandRun replay =
      Saccade("run " + kPipelines + "perception.yaml --dds-domain " + GetParam().replay_domain +
              head + " --play " + Path("robot.mcap") + " --record " + Path("replay.mcap"));
  ASSERT_EQ(replay.status, 0) << replay.output;
  EXPECT_THAT(replay.output, HasSubstr("play: " + std::to_string(kSteps) + " steps"));
  EXPECT_THAT(replay.output, ::testing::Not(HasSubstr("answered late")));
  if (!GetParam().head.empty()) {
    // The robot's recording is of that head: its joints on joint_states.
    const record::McapReader reader(Path("robot.mcap"));
    ASSERT_FALSE(reader.metadata().empty());
    EXPECT_EQ(reader.metadata().front().values.at("head"), "humanoid");
  }

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

INSTANTIATE_TEST_SUITE_P(Heads, ReplayCli,
                         ::testing::Values(ReplayCase{"popeye", "", "214", "215"},
                                           ReplayCase{"humanoid", kSource + "/robots/humanoid.yaml",
                                                      "218", "219"}),
                         [](const auto& info) { return std::string(info.param.name); });

// Exploration over DDS (pipelines/explore_perception.yaml, issue 44): live, against the
// simulated robot on the wall scene, it fuses a depth at each rest into a map; the robot's
// recording played back into it in lockstep (recorded cameras) builds the same maps, byte for
// byte, and sends the same commands.
TEST_F(RecordCli, ExplorationOnLiveAndOnRecordedCamerasBuildsTheSameMap) {
  constexpr int kSteps = 40;
  const std::string scene = " --scene " + kSource + "/scenes/explore_wall.yaml";
  BackgroundProcess explore({kBinary, "run", kPipelines + "explore_perception.yaml", "--dds-domain",
                             "223", "--steps", std::to_string(kSteps), "--scene",
                             kSource + "/scenes/explore_wall.yaml", "--record", Path("live.mcap")});
  const CommandRun robot =
      Saccade("run " + kPipelines + "robot.yaml --dds-domain 223 --steps " +
              std::to_string(kSteps) + scene + " --record " + Path("robot.mcap"));
  ASSERT_EQ(robot.status, 0) << robot.output;
  std::string explore_output;
  while (const auto line = explore.ReadLine(std::chrono::seconds(120))) explore_output += *line;
  const CommandRun replay =
      Saccade("run " + kPipelines + "explore_perception.yaml --dds-domain 224" + scene +
              " --play " + Path("robot.mcap") + " --record " + Path("replay.mcap"));
  ASSERT_EQ(replay.status, 0) << replay.output;

  const auto live = MessagesByTopic(Path("live.mcap"));
  const auto replayed = MessagesByTopic(Path("replay.mcap"));
  for (const char* topic :
       {"/saccade/map/map", "/saccade/map/map/inhibited", "/saccade/depth/depth",
        "/saccade/explore/selection", "/saccade/fixation/command"}) {
    SCOPED_TRACE(topic);
    ASSERT_TRUE(live.count(topic)) << explore_output;
    ASSERT_TRUE(replayed.count(topic)) << replay.output;
    // Live, the run may end before the robot's last images reached it (they wait at most
    // wait_s, then the step passes): the runs agree up to there.
    const auto& a = live.at(topic);
    const auto& b = replayed.at(topic);
    ASSERT_LE(std::max(a.size(), b.size()) - std::min(a.size(), b.size()), 1u);
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
      ASSERT_EQ(a[i], b[i]) << "message " << i;
    }
  }
  // The maps grew at each rest: at least three sensor_msgs/PointCloud2 (16 bytes a point),
  // the last holding thousands of voxels; the inhibited places beside each.
  const auto& maps = live.at("/saccade/map/map");
  ASSERT_GE(maps.size(), 3u);
  EXPECT_GT(maps.back().size(), maps.front().size());
  EXPECT_GT(maps.back().size(), 2000u * 16);
  ASSERT_TRUE(live.count("/saccade/map/map/inhibited"));
  EXPECT_EQ(live.at("/saccade/map/map/inhibited").size(), maps.size());
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
    const int after_ms = 500 + static_cast<int>(rng() % 4000);
    SCOPED_TRACE("killed " + std::to_string(after_ms) + " ms after the file appeared");
    BackgroundProcess run({kBinary, "run", kPipelines + "demo.yaml", "--steps", "0", "--record",
                           file, "--record-chunk-s", "0.2"});
    // From the moment the recording exists: the start-up (scene, GL) takes seconds on a loaded
    // machine, and a process killed before it made the file left nothing to read.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!fs::exists(file) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_TRUE(fs::exists(file)) << "saccade run made no recording in 60 s";
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

// `saccade render --record` writes what `--out` writes: `mcap export` of the recording gives
// back the data set's images, depth and id truth pixel for pixel, and each frame's record
// (/saccade/frames) is frames.jsonl's line without the file names. With the humanoid head.
TEST_F(RecordCli, RenderRecordsItsFramesAndExportGivesTheDataSetBackPixelForPixel) {
  const std::string scene = kSource + "/scenes/portraits.yaml";
  const std::string head = " --head " + kSource + "/robots/humanoid.yaml";
  EXPECT_THAT(Saccade("render --scene " + scene + " --frames 1").output,
              HasSubstr("give --out DIR, --record FILE.mcap or both"));
  const std::string file = Path("render.mcap");
  const CommandRun render =
      Saccade("render --scene " + scene + head + " --frames 3 --truth depth,ids,boxes --out " +
              Path("set") + " --record " + file);
  ASSERT_EQ(render.status, 0) << render.output;
  EXPECT_THAT(render.output, HasSubstr(file));
  const CommandRun exported = Saccade("mcap export " + file + " --out " + Path("exported"));
  ASSERT_EQ(exported.status, 0) << exported.output;

  std::ifstream set_index(Path("set") + "/frames.jsonl");
  std::ifstream exported_index(Path("exported") + "/frames.jsonl");
  std::vector<json> set, out;
  for (std::string line; std::getline(set_index, line);) set.push_back(json::parse(line));
  for (std::string line; std::getline(exported_index, line);) out.push_back(json::parse(line));
  ASSERT_EQ(set.size(), 3u);
  ASSERT_EQ(out.size(), 3u);
  int images = 0;
  for (std::size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(set[i]["cameras"].size(), out[i]["cameras"].size());
    for (const auto& [camera, entry] : set[i]["cameras"].items()) {
      SCOPED_TRACE(camera + " frame " + std::to_string(i));
      const json& other = out[i]["cameras"][camera];
      EXPECT_EQ(entry["K"], other["K"]);
      for (const char* key : {"file", "depth", "ids"}) {
        const cv::Mat a =
            cv::imread(Path("set") + "/" + entry[key].get<std::string>(), cv::IMREAD_UNCHANGED);
        const cv::Mat b = cv::imread(Path("exported") + "/" + other[key].get<std::string>(),
                                     cv::IMREAD_UNCHANGED);
        ASSERT_FALSE(a.empty()) << key;
        ASSERT_EQ(a.type(), b.type()) << key;
        ASSERT_EQ(a.size(), b.size()) << key;
        EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << key;
        EXPECT_GT(cv::countNonZero(a.reshape(1)), 0) << key;
        ++images;
      }
    }
  }
  EXPECT_EQ(images, 3 * 3 * 3);  // frames x cameras (left, right, overview) x (image, depth, ids)

  const record::McapReader reader(file);
  EXPECT_EQ(reader.metadata().front().values.at("command"), "render");
  EXPECT_EQ(reader.metadata().front().values.at("head"), "humanoid");
  std::vector<json> records;
  reader.ForEachMessage([&](const record::McapMessage& m) {
    if (reader.channels().at(m.channel_id).topic == "/saccade/frames") {
      records.push_back(json::parse(m.data.begin(), m.data.end()));
    }
    return true;
  });
  ASSERT_EQ(records.size(), 3u);
  for (std::size_t i = 0; i < set.size(); ++i) {
    json expected = set[i];
    for (auto& [camera, entry] : expected["cameras"].items()) {
      for (const char* key : {"file", "depth", "ids"}) entry.erase(key);
    }
    EXPECT_EQ(records[i], expected) << "frame " << i;
  }

  // An existing recording is kept without --force, and nothing else is written.
  const auto size = fs::file_size(file);
  const CommandRun again =
      Saccade("render --scene " + scene + " --out " + Path("set2") + " --record " + file);
  EXPECT_EQ(again.status, 1);
  EXPECT_THAT(again.output, HasSubstr("the file exists; --force replaces it"));
  EXPECT_EQ(fs::file_size(file), size);
  EXPECT_FALSE(fs::exists(Path("set2")));
}

// A camera with a colour filter array: `render --record` carries its raw mosaic, and `mcap
// export` gives back `--out`'s raw/ images pixel for pixel with the pattern, and each camera's
// exposure, gain and focus from the frames' records.
TEST_F(RecordCli, RenderRecordsTheRawMosaicAndExportGivesItBackWithTheCameraControls) {
  const std::string scene = Path("bayer.yaml");
  std::ofstream(scene) << "lights: [{type: ambient, intensity: 1}]\n"
                          "ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2]}\n"
                          "cameras:\n"
                          "  - name: eye\n"
                          "    calibration: {width: 64, height: 48, fx: 50, fy: 50}\n"
                          "    look_at: {eye: [0, 0, 1], target: [2, 0, 0]}\n"
                          "    lens: {f_number: 2.8, focal_length_mm: 4, focus_distance: 2.5}\n"
                          "    sensor: {exposure_ms: 5, blur_samples: 1, read_noise_dn: 1,\n"
                          "             color: {cfa: gbrg}}\n";
  const std::string file = Path("raw.mcap");
  const CommandRun render =
      Saccade("render --scene " + scene + " --frames 2 --out " + Path("set") + " --record " + file);
  ASSERT_EQ(render.status, 0) << render.output;
  const CommandRun exported = Saccade("mcap export " + file + " --out " + Path("exported"));
  ASSERT_EQ(exported.status, 0) << exported.output;
  std::ifstream set_index(Path("set") + "/frames.jsonl");
  std::ifstream exported_index(Path("exported") + "/frames.jsonl");
  std::vector<json> set, out;
  for (std::string line; std::getline(set_index, line);) set.push_back(json::parse(line));
  for (std::string line; std::getline(exported_index, line);) out.push_back(json::parse(line));
  ASSERT_EQ(set.size(), 2u);
  ASSERT_EQ(out.size(), 2u);
  for (std::size_t i = 0; i < set.size(); ++i) {
    SCOPED_TRACE(i);
    const json& a = set[i]["cameras"]["eye"];
    const json& b = out[i]["cameras"]["eye"];
    EXPECT_EQ(b["cfa"], "gbrg");
    EXPECT_EQ(a["cfa"], b["cfa"]);
    EXPECT_EQ(a["exposure_s"], 0.005);
    EXPECT_EQ(a["focus_m"], 2.5);
    for (const char* key : {"exposure_samples", "exposure_s", "gain_db", "focus_m"}) {
      EXPECT_EQ(a[key], b[key]) << key;
    }
    const cv::Mat x =
        cv::imread(Path("set") + "/" + a["raw"].get<std::string>(), cv::IMREAD_UNCHANGED);
    const cv::Mat y =
        cv::imread(Path("exported") + "/" + b["raw"].get<std::string>(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(x.empty());
    ASSERT_EQ(y.type(), CV_8UC1);
    ASSERT_EQ(x.size(), y.size());
    EXPECT_EQ(cv::norm(x, y, cv::NORM_INF), 0.0);
  }
  const auto topics = MessagesByTopic(file);
  ASSERT_TRUE(topics.count("/saccade/eye/raw/image_raw"));
  EXPECT_EQ(topics.at("/saccade/eye/raw/image_raw").size(), 2u);
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
