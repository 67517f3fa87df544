// A pipeline's run recorded to MCAP (record/recorder.h), checked by parts nobody here wrote:
// Foxglove's @mcap/core reads the file under Node (every CRC checked, through the summary and
// the indexes), its ROS 2 parser reads the schemas (compared with common_interfaces' definitions
// of @foxglove/rosmsg-msgs-common) and @foxglove/rosmsg2-serialization decodes every message,
// which must be what the pipeline sent: images byte for byte (hashed), joints to the bit.
#include "saccade/record/recorder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "record/run_node.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/topics.h"
#include "saccade/record/mcap.h"
#include "saccade/record/player.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "scratch_dir.h"

namespace saccade::record {
namespace {

namespace fs = std::filesystem;
using components::JointStateMessage;
using components::TargetMessage;
using nlohmann::json;
using ::testing::HasSubstr;

const std::string kSource = SACCADE_SOURCE_DIR;

fs::path TempFile(const std::string& name) { return testing_helpers::ScratchFile(name); }

// The reference script's output for `command` on `file`; its exit status in `*status`.
std::string Node(const std::string& command, const fs::path& file, int* status) {
  return testing::RunNode("mcap_reference.mjs", command + " '" + file.string() + "'", status);
}

uint32_t Fnv1a(const uint8_t* bytes, std::size_t size) {
  uint32_t h = 0x811c9dc5u;
  for (std::size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 0x01000193u;
  return h;
}

int64_t StampNs(const json& stamp) {
  return stamp["sec"].get<int64_t>() * 1'000'000'000 + stamp["nanosec"].get<int64_t>();
}

// What the pipeline sent, as the decoded messages must give it back.
struct Sent {
  std::map<std::string, std::vector<json>> images;  // by camera: stamp, size, pixels' hash
  std::vector<json> joints;                         // names, positions, velocities
  std::vector<json> targets;                        // valid targets' points
};

void TapSent(runtime::Pipeline& pipeline, Sent* sent) {
  for (const auto& c : pipeline.components()) {
    for (const auto& o : c->outputs()) {
      if (c->name() == "cameras") {
        if (auto* i = dynamic_cast<runtime::Output<runtime::ImageMessage>*>(o.get())) {
          i->signal().Connect([sent](const runtime::ImageMessage& m) {
            const Image& image = *m.image;
            sent->images[image.metadata().camera].push_back(
                {{"stamp", std::llround(image.metadata().time * 1e9)},
                 {"width", image.width()},
                 {"height", image.height()},
                 {"fnv1a", Fnv1a(image.data(), image.size_bytes())}});
          });
        }
      }
      if (auto* j = dynamic_cast<runtime::Output<JointStateMessage>*>(o.get())) {
        j->signal().Connect([sent](const JointStateMessage& m) {
          sent->joints.push_back({{"name", m.positions.names()},
                                  {"position", m.positions.values()},
                                  {"velocity", m.velocities.values()}});
        });
      }
      if (auto* t = dynamic_cast<runtime::Output<TargetMessage>*>(o.get())) {
        t->signal().Connect([sent](const TargetMessage& m) {
          if (m.valid) sent->targets.push_back({m.p_W.x(), m.p_W.y(), m.p_W.z()});
        });
      }
    }
  }
}

TEST(PipelineRecorder, TheDemosRecordingDecodesInFoxglovesReadersToWhatItSent) {
  components::RegisterComponents();
  runtime::PipelineSpec spec = runtime::LoadPipelineFile(kSource + "/pipelines/demo.yaml");
  runtime::Pipeline pipeline = runtime::Pipeline::Build(spec);
  const fs::path file = TempFile("demo.mcap");
  Sent sent;
  TapSent(pipeline, &sent);
  RecorderOptions options;
  options.chunk_seconds = 0.1;
  options.metadata = {{"pipeline", "pipelines/demo.yaml"}};
  PipelineRecorder recorder(pipeline, file, options);
  runtime::RunOptions run;
  run.steps = 12;
  run.after_step = [&](const runtime::StepContext& context) {
    recorder.AddJson("/saccade/ground_truth", context.time, {{"step", context.step}});
    recorder.AfterStep(context);
  };
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, run);
  ASSERT_TRUE(summary.errors.empty());
  const RecordingStats stats = recorder.Close();
  EXPECT_EQ(stats.steps, 12);
  EXPECT_EQ(stats.bytes, fs::file_size(file));

  int status = 0;
  const std::string out = Node("decode", file, &status);
  ASSERT_EQ(status, 0) << out.substr(0, 2000);
  const json decoded = json::parse(out);

  // The schemas are ROS 2's: each parses, and agrees with common_interfaces' definitions.
  for (const char* type :
       {"sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo", "sensor_msgs/msg/JointState",
        "geometry_msgs/msg/PointStamped", "tf2_msgs/msg/TFMessage", "std_msgs/msg/String"}) {
    ASSERT_TRUE(decoded["schemas"].contains(type)) << type;
    EXPECT_EQ(decoded["schemas"][type], json::array()) << type;
  }
  EXPECT_EQ(decoded["metadata"]["saccade"]["pipeline"], "pipelines/demo.yaml");

  // Every message, in the order recorded; the counts are the summary's.
  const McapReader reader(file);
  EXPECT_FALSE(reader.recovered());
  EXPECT_EQ(decoded["message_count"], std::to_string(reader.statistics().message_count));
  EXPECT_EQ(decoded["messages"].size(), reader.statistics().message_count);
  std::map<std::string, std::vector<json>> by_topic;
  for (const json& m : decoded["messages"]) {
    by_topic[m["topic"].get<std::string>()].push_back(m);
  }
  for (const auto& [camera, images] : sent.images) {
    SCOPED_TRACE(camera);
    const auto& got = by_topic["/saccade/" + camera + "/image_raw"];
    const auto& infos = by_topic["/saccade/" + camera + "/camera_info"];
    ASSERT_EQ(got.size(), images.size());
    ASSERT_EQ(infos.size(), images.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      const json& v = got[i]["value"];
      EXPECT_EQ(StampNs(v["header"]["stamp"]), images[i]["stamp"]) << i;
      EXPECT_EQ(got[i]["publish_time"], std::to_string(images[i]["stamp"].get<int64_t>()));
      EXPECT_EQ(v["header"]["frame_id"], camera + "_optical");
      EXPECT_EQ(v["width"], images[i]["width"]);
      EXPECT_EQ(v["height"], images[i]["height"]);
      EXPECT_EQ(v["encoding"], "rgb8");
      EXPECT_EQ(v["data"]["fnv1a"], images[i]["fnv1a"]) << i;
      EXPECT_EQ(infos[i]["value"]["width"], images[i]["width"]);
    }
  }
  const auto& joints = by_topic["/saccade/joint_states"];
  ASSERT_EQ(joints.size(), sent.joints.size());
  ASSERT_GE(joints.size(), 12u);
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const json& v = joints[i]["value"];
    EXPECT_EQ(v["name"], sent.joints[i]["name"]);
    // Doubles to the bit: JSON carries each in its shortest exact form.
    const auto positions = v["position"].get<std::vector<double>>();
    const auto expected = sent.joints[i]["position"].get<std::vector<double>>();
    ASSERT_EQ(positions.size(), expected.size());
    for (std::size_t k = 0; k < positions.size(); ++k) {
      EXPECT_EQ(std::bit_cast<uint64_t>(positions[k]), std::bit_cast<uint64_t>(expected[k]));
    }
    EXPECT_EQ(v["velocity"].get<std::vector<double>>(),
              sent.joints[i]["velocity"].get<std::vector<double>>());
  }
  EXPECT_EQ(by_topic["/saccade/joint_targets"].size(), joints.size());
  ASSERT_EQ(by_topic["/saccade/robot_description"].size(), 1u);
  EXPECT_THAT(by_topic["/saccade/robot_description"][0]["value"]["data"].get<std::string>(),
              HasSubstr("<robot name=\"popeye\""));
  const auto& targets = by_topic["/saccade/triangulate/target"];
  ASSERT_EQ(targets.size(), sent.targets.size());
  ASSERT_FALSE(targets.empty());
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const json& p = targets[i]["value"]["point"];
    EXPECT_EQ(json::array({p["x"], p["y"], p["z"]}), sent.targets[i]);
  }
  // The TF of both optical frames and of every link; detections and the extra channel in JSON.
  EXPECT_GE(by_topic["/tf"].size(), 3 * 12u);
  EXPECT_EQ(by_topic["/saccade/faces_left/faces"].size(), 12u);
  ASSERT_EQ(by_topic["/saccade/ground_truth"].size(), 12u);
  EXPECT_EQ(by_topic["/saccade/ground_truth"][5]["value"]["step"], 5);
  // Each message is logged at its step's time.
  EXPECT_EQ(by_topic["/saccade/ground_truth"][5]["log_time"], "200000000");
  EXPECT_EQ(by_topic["/saccade/left/image_raw"][5]["log_time"], "200000000");
}

// A map output (mapping.map, here debug.map's) is recorded as the DDS writer sends it:
// sensor_msgs/PointCloud2 on its topic and the inhibited places on `<topic>/inhibited`, with a
// schema that Foxglove's reader parses and finds equal to common_interfaces' definition.
TEST(PipelineRecorder, MapsAreRecordedAsPointCloud2WithTheirInhibitedPlaces) {
  components::RegisterComponents();
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(
      "clock: {mode: simulated, step: 0.1, steps: 3}\n"
      "components:\n"
      "  - {name: mapper, type: debug.map, params: {voxels_per_step: 4, inhibit_every_steps: 1}}\n",
      "map.yaml");
  const fs::path file = TempFile("map.mcap");
  PipelineRecorder recorder(pipeline, file);
  runtime::RunOptions run;
  run.steps = 3;
  run.after_step = [&](const runtime::StepContext& context) { recorder.AfterStep(context); };
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, run);
  ASSERT_TRUE(summary.errors.empty());
  recorder.Close();

  int status = 0;
  const std::string out = Node("decode", file, &status);
  ASSERT_EQ(status, 0) << out.substr(0, 2000);
  const json decoded = json::parse(out);
  ASSERT_TRUE(decoded["schemas"].contains("sensor_msgs/msg/PointCloud2"));
  EXPECT_EQ(decoded["schemas"]["sensor_msgs/msg/PointCloud2"], json::array());
  std::map<std::string, std::vector<json>> by_topic;
  for (const json& m : decoded["messages"]) {
    by_topic[m["topic"].get<std::string>()].push_back(m);
  }
  const auto& maps = by_topic["/saccade/mapper/map"];
  const auto& inhibited = by_topic["/saccade/mapper/map/inhibited"];
  ASSERT_EQ(maps.size(), 3u);
  ASSERT_EQ(inhibited.size(), 3u);
  const json& last = maps[2]["value"];
  EXPECT_EQ(last["header"]["frame_id"], "world");
  EXPECT_EQ(StampNs(last["header"]["stamp"]), 200'000'000);
  EXPECT_EQ(last["width"], 12);  // 4 voxels a step
  EXPECT_EQ(last["point_step"], 16);
  std::vector<std::string> fields;
  for (const json& f : last["fields"]) fields.push_back(f["name"]);
  EXPECT_EQ(fields, (std::vector<std::string>{"x", "y", "z", "rgb"}));
  EXPECT_EQ(inhibited[2]["value"]["width"], 3);  // a place a step, none forgotten yet
  EXPECT_EQ(inhibited[2]["value"]["point_step"], 20);
}

// sim.cameras' raw mosaic (`raw: true`) is recorded beside its camera's image, as render
// --record's depth: `/saccade/<camera>/raw/image_raw`, sensor_msgs/Image with ROS's Bayer
// encoding and the mosaic's bytes (Foxglove's reader), its camera info, no second pose on /tf;
// played back (McapPlayer), a DDS reader receives the mosaic again, byte for byte.
TEST(PipelineRecorder, RawMosaicsAreRecordedWithTheirBayerEncodingAndPlayBack) {
  setenv("CYCLONEDDS_URI", "file://" SACCADE_SOURCE_DIR "/config/dds/loopback.xml", 0);
  components::RegisterComponents();
  const std::string scene = TempFile("bayer.yaml").string();
  std::ofstream(scene) << "lights: [{type: ambient, intensity: 1}]\n"
                          "ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2]}\n"
                          "cameras:\n"
                          "  - name: eye\n"
                          "    calibration: {width: 64, height: 48, fx: 50, fy: 50}\n"
                          "    look_at: {eye: [0, 0, 1], target: [2, 0, 0]}\n"
                          "    sensor: {exposure_ms: 6, color: {cfa: rggb}}\n"
                          "    lens: {f_number: 2.8, focal_length_mm: 6, focus_distance: 1.5}\n";
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(
      "clock: {mode: simulated, step: 0.04, steps: 3}\n"
      "components:\n"
      "  - {name: cameras, type: sim.cameras, params: {scene: " +
          scene + ", cameras: [eye], raw: true}}\n",
      "raw.yaml");
  std::vector<std::shared_ptr<const Image>> raws;
  auto* raw_output = dynamic_cast<runtime::Output<runtime::ImageMessage>*>(
      pipeline.components().at(0)->FindOutput("eye_raw"));
  ASSERT_NE(raw_output, nullptr);
  raw_output->signal().Connect([&](const runtime::ImageMessage& m) { raws.push_back(m.image); });
  const fs::path file = TempFile("raw.mcap");
  {
    PipelineRecorder recorder(pipeline, file);
    runtime::RunOptions run;
    run.after_step = [&](const runtime::StepContext& context) { recorder.AfterStep(context); };
    const runtime::RunSummary summary = runtime::RunPipeline(pipeline, run);
    ASSERT_TRUE(summary.errors.empty());
    recorder.Close();
  }
  ASSERT_EQ(raws.size(), 3u);

  int status = 0;
  const std::string out = Node("decode", file, &status);
  ASSERT_EQ(status, 0) << out.substr(0, 2000);
  const json decoded = json::parse(out);
  std::map<std::string, std::vector<json>> by_topic;
  for (const json& m : decoded["messages"]) {
    by_topic[m["topic"].get<std::string>()].push_back(m);
  }
  const auto& mosaics = by_topic["/saccade/eye/raw/image_raw"];
  ASSERT_EQ(mosaics.size(), 3u);
  for (std::size_t i = 0; i < mosaics.size(); ++i) {
    const json& v = mosaics[i]["value"];
    const Image& sent = *raws[i];
    EXPECT_EQ(StampNs(v["header"]["stamp"]), std::llround(sent.metadata().time * 1e9)) << i;
    EXPECT_EQ(v["header"]["frame_id"], "eye_optical");
    EXPECT_EQ(v["encoding"], "bayer_rggb8");
    EXPECT_EQ(v["width"], 64);
    EXPECT_EQ(v["height"], 48);
    EXPECT_EQ(v["step"], 64);
    EXPECT_EQ(v["data"]["fnv1a"], Fnv1a(sent.data(), sent.size_bytes())) << i;
  }
  EXPECT_EQ(by_topic["/saccade/eye/image_raw"].size(), 3u);
  EXPECT_EQ(by_topic["/saccade/eye/image_raw"][0]["value"]["encoding"], "rgb8");
  EXPECT_EQ(by_topic["/saccade/eye/raw/camera_info"].size(), 3u);
  EXPECT_EQ(by_topic["/tf"].size(), 3u);  // the eye's pose once a frame, from its image
  // Each step's frame record (/saccade/frames, JSON, as render --record's): what an Image
  // cannot carry, the camera controls each image was taken with, from its metadata.
  const auto& records = by_topic["/saccade/frames"];
  ASSERT_EQ(records.size(), 3u);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const ImageMetadata& m = raws[i]->metadata();
    const json& eye = records[i]["value"]["cameras"]["eye"];
    EXPECT_EQ(records[i]["value"]["frame"], m.frame_index) << i;
    EXPECT_EQ(records[i]["value"]["time"], m.time) << i;
    EXPECT_EQ(eye["exposure_s"], 0.006) << i;
    EXPECT_EQ(eye["exposure_s"], m.exposure_s) << i;
    EXPECT_EQ(eye["gain_db"], m.gain_db) << i;
    EXPECT_EQ(eye["focus_m"], 1.5) << i;
    EXPECT_EQ(eye["exposure_samples"], m.exposure_samples) << i;
    EXPECT_EQ(eye["width"], 64) << i;
  }

  // Played back on DDS: the player's writers keep the last 2 images for later readers.
  constexpr int kDomain = 226;
  PlayOptions fast;
  fast.pace = "fast";
  McapPlayer player(file, {{"domain", kDomain}}, fast);
  player.Start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!player.stats().finished && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(player.stats().finished);
  dds::DomainOptions domain;
  domain.domain_id = kDomain;
  dds::TopicOptions topic;
  topic.topic = "/saccade/eye/raw/image_raw";
  topic.qos = dds::Qos::Images();
  topic.qos.durability = dds::Durability::kTransientLocal;
  auto reader = dds::Reader::Create(dds::Participant::Create(domain), "runtime.image", topic);
  const auto back = reader->Take<runtime::ImageMessage>(10.0);
  ASSERT_TRUE(back && back->image);
  const Image& last = *raws.back();
  EXPECT_EQ(back->image->format(), PixelFormat::kBayerRggb8);
  EXPECT_EQ(back->image->metadata().camera, "eye");
  EXPECT_DOUBLE_EQ(back->image->metadata().time, last.metadata().time);
  ASSERT_EQ(back->image->size_bytes(), last.size_bytes());
  EXPECT_EQ(std::memcmp(back->image->data(), last.data(), last.size_bytes()), 0);
  player.Stop();
}

TEST(PipelineRecorder, OptionsOutOfRangeAndUnwritableFilesAreRefused) {
  components::RegisterComponents();
  runtime::PipelineSpec spec = runtime::LoadPipelineFile(kSource + "/pipelines/demo.yaml");
  runtime::Pipeline pipeline = runtime::Pipeline::Build(spec);
  RecorderOptions lz5;
  lz5.compression = "lz5";
  EXPECT_THROW(
      {
        try {
          PipelineRecorder(pipeline, TempFile("a.mcap"), lz5);
        } catch (const InvalidArgument& e) {
          EXPECT_THAT(e.what(), HasSubstr("'lz5'"));
          throw;
        }
      },
      InvalidArgument);
  RecorderOptions zero;
  zero.chunk_seconds = 0.0;
  EXPECT_THROW(PipelineRecorder(pipeline, TempFile("b.mcap"), zero), InvalidArgument);
  EXPECT_FALSE(fs::exists(TempFile("a.mcap")));
  try {
    PipelineRecorder(pipeline, "/nonexistent-dir/run.mcap");
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent-dir/run.mcap"));
  }
}

}  // namespace
}  // namespace saccade::record
