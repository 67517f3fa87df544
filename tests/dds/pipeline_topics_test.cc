// Pipeline connections that name a DDS topic (runtime/pipeline.h, dds/transport.h): a plain
// ROS 2-typed publisher drives a pipeline's head, and bad topic connections are reported at
// their file and line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <thread>

#include "dds_test_util.h"
#include "saccade/components/demo/loop_outputs.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/dds/transport.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "scratch_dir.h"

namespace saccade::dds {
namespace {

using ::testing::HasSubstr;
using namespace saccade::dds::testing;

const std::string kScene = SACCADE_SOURCE_DIR "/scenes/portraits.yaml";

std::string HeadPipeline(int domain, const std::string& command_input) {
  return "clock: {mode: simulated, step: 0.04, steps: 50}\n"
         "scene: " +
         kScene +
         "\n"
         "transport: {domain: " +
         std::to_string(domain) +
         ", namespace: /saccade}\n"
         "components:\n"
         "  - name: head\n"
         "    type: sim.head\n"
         "    inputs:\n"
         "      command: " +
         command_input +
         "\n"
         "    outputs: {joints: joint_states}\n";
}

class PipelineTopics : public ::testing::Test {
 protected:
  void SetUp() override {
    PinLoopback();
    components::RegisterComponents();
    RegisterDdsTransport(runtime::ComponentRegistry::Global());
  }
};

TEST_F(PipelineTopics, PlainPublisherOfJointStateCommandsMovesTheHead) {
  constexpr int kDomain = 181;
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(
      HeadPipeline(kDomain, "{topic: head/command, start_wait_s: 10}"), "head.yaml");
  // The reader of the topic is a component just before the head.
  ASSERT_EQ(pipeline.components().size(), 2u);
  EXPECT_EQ(pipeline.components()[0]->name(), "head-command-topic");

  // A plain Cyclone DDS program of the ROS 2 types commands pan 0.2 rad, tilt -0.1 rad.
  Raw raw(RawParticipant(kDomain));
  Raw writer(
      RawWriter(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc, "rt/saccade/head/command"));
  Raw joints(RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc,
                       "rt/saccade/joint_states", 100, /*transient_local=*/true));
  ASSERT_TRUE(WaitWriterMatched(writer.get()));
  char* names[4] = {const_cast<char*>("pan"), const_cast<char*>("tilt"), const_cast<char*>("left"),
                    const_cast<char*>("right")};
  double position[4] = {0.2, -0.1, 0.05, -0.05};
  ref_sensor_msgs_msg_dds__JointState_ command{};
  command.header.frame_id = const_cast<char*>("");
  command.name = {4, 4, names, false};
  command.position = {4, 4, position, false};
  ASSERT_EQ(dds_write(writer.get(), &command), DDS_RETCODE_OK);

  std::optional<components::JointStateMessage> last;
  components::demo::Tap<components::JointStateMessage>(
      pipeline, [&](const components::JointStateMessage& m) { last = m; });
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline);
  ASSERT_EQ(summary.errors_total, 0);
  ASSERT_TRUE(last.has_value());
  // 2 s is ample for sim.head's motors to get there (they move at rad/s).
  constexpr double kArrived = 1e-3;  // rad
  EXPECT_NEAR(last->positions.at("pan"), 0.2, kArrived);
  EXPECT_NEAR(last->positions.at("tilt"), -0.1, kArrived);
  EXPECT_NEAR(last->positions.at("left"), 0.05, kArrived);
  EXPECT_NEAR(last->positions.at("right"), -0.05, kArrived);

  // And the head's state went out on joint_states, as ROS 2's JointState.
  ref_sensor_msgs_msg_dds__JointState_ state{};
  ASSERT_TRUE(TakeSample(joints.get(), &state));
  EXPECT_EQ(state.name._length, 4u);
  EXPECT_STREQ(state.name._buffer[0], "pan");
  dds_sample_free(&state, &ref_sensor_msgs_msg_dds__JointState__desc, DDS_FREE_CONTENTS);
}

// The receiving half of a split pipeline steps on the sender's stamps (clock.source): each
// step's time is the stamp of the message its reader took for it, that message is the one the
// step hands on, and a step that received nothing goes on one clock step later.
TEST_F(PipelineTopics, ClockSourceStepsOnTheReceivedStamps) {
  constexpr int kDomain = 184;
  std::string text = HeadPipeline(kDomain, "{topic: head/command, wait_s: 1, start_wait_s: 10}");
  text.replace(text.find("steps: 50}"), 10, "steps: 5, source: head.command}");
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(text, "head.yaml");
  ASSERT_NE(pipeline.time_source(), nullptr);

  Raw raw(RawParticipant(kDomain));
  Raw writer(
      RawWriter(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc, "rt/saccade/head/command"));
  ASSERT_TRUE(WaitWriterMatched(writer.get()));
  // A command stamped `seconds` pans to seconds / 10 rad.
  const auto Send = [&](int32_t sec, uint32_t nanosec) {
    char* names[4] = {const_cast<char*>("pan"), const_cast<char*>("tilt"),
                      const_cast<char*>("left"), const_cast<char*>("right")};
    double position[4] = {(sec + 1e-9 * nanosec) / 10.0, 0.0, 0.0, 0.0};
    ref_sensor_msgs_msg_dds__JointState_ command{};
    command.header.stamp.sec = sec;
    command.header.stamp.nanosec = nanosec;
    command.header.frame_id = const_cast<char*>("");
    command.name = {4, 4, names, false};
    command.position = {4, 4, position, false};
    ASSERT_EQ(dds_write(writer.get(), &command), DDS_RETCODE_OK);
  };
  Send(1, 0);
  std::vector<double> times;
  std::vector<double> targets;  // the head's pan target after each step
  components::demo::Tap<components::JointStateMessage>(
      pipeline,
      [&](const components::JointStateMessage& m) { targets.push_back(m.targets.at("pan")); });
  runtime::RunOptions options;
  options.after_step = [&](const runtime::StepContext& context) {
    times.push_back(context.time);
    // After step 2 the sender says nothing: step 3 waits its second and goes on.
    if (context.step == 0) Send(1, 500000000);
    if (context.step == 1) Send(2, 0);
    if (context.step == 3) Send(3, 0);
  };
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, options);
  ASSERT_EQ(summary.errors_total, 0) << summary.FullReport();
  EXPECT_THAT(times, ::testing::ElementsAre(1.0, 1.5, 2.0, 2.04, 3.0));
  EXPECT_DOUBLE_EQ(summary.sim_time, 3.0);
  // Each step handed on the message whose stamp timed it (step 3 had none: the target stays).
  EXPECT_THAT(targets, ::testing::ElementsAre(::testing::DoubleEq(0.1), ::testing::DoubleEq(0.15),
                                              ::testing::DoubleEq(0.2), ::testing::DoubleEq(0.2),
                                              ::testing::DoubleEq(0.3)));
}

// With no sender, a pipeline stepping on its stamps has nothing to time its steps: each waits
// its wait_s for a sender (instead of spinning through empty steps at full speed), and one that
// comes is picked up at once.
TEST_F(PipelineTopics, ClockSourceWithoutASenderWaitsForOne) {
  constexpr int kDomain = 187;
  std::string text = HeadPipeline(kDomain, "{topic: head/command, wait_s: 0.2}");
  text.replace(text.find("steps: 50}"), 10, "steps: 3, source: head.command}");
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(text, "head.yaml");
  const runtime::RunSummary alone = runtime::RunPipeline(pipeline);
  ASSERT_EQ(alone.errors_total, 0) << alone.FullReport();
  EXPECT_EQ(alone.steps, 3);
  EXPECT_GE(alone.wall_seconds, 3 * 0.2);  // each step waited its wait_s

  // A sender that comes during the wait: its first message times the step.
  text = HeadPipeline(kDomain, "{topic: head/command, wait_s: 60}");
  text.replace(text.find("steps: 50}"), 10, "steps: 1, source: head.command}");
  runtime::Pipeline waiting = runtime::Pipeline::LoadString(text, "head.yaml");
  std::thread sender([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    Raw raw(RawParticipant(kDomain));
    Raw writer(RawWriter(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc,
                         "rt/saccade/head/command"));
    ASSERT_TRUE(WaitWriterMatched(writer.get()));
    char* names[4] = {const_cast<char*>("pan"), const_cast<char*>("tilt"),
                      const_cast<char*>("left"), const_cast<char*>("right")};
    double position[4] = {0.1, 0.0, 0.0, 0.0};
    ref_sensor_msgs_msg_dds__JointState_ command{};
    command.header.stamp.sec = 7;
    command.header.frame_id = const_cast<char*>("");
    command.name = {4, 4, names, false};
    command.position = {4, 4, position, false};
    ASSERT_EQ(dds_write(writer.get(), &command), DDS_RETCODE_OK);
    std::this_thread::sleep_for(std::chrono::seconds(2));  // until the step took it
  });
  const runtime::RunSummary joined = runtime::RunPipeline(waiting);
  sender.join();
  ASSERT_EQ(joined.errors_total, 0) << joined.FullReport();
  EXPECT_DOUBLE_EQ(joined.sim_time, 7.0);
  EXPECT_LT(joined.wall_seconds, 60.0);  // picked up, not waited out
}

TEST_F(PipelineTopics, ClockSourceMustBeATopicInputOfASimulatedClock) {
  const auto ErrorOf = [](const std::string& clock, const std::string& command_input) {
    std::string text = HeadPipeline(185, command_input);
    text.replace(0, text.find('\n'), "clock: " + clock);
    try {
      runtime::Pipeline::LoadString(text, "head.yaml");
    } catch (const FileError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const std::string topic = "{topic: head/command}";
  EXPECT_EQ(ErrorOf("{mode: simulated, steps: 1, source: head.command}", topic), "(no error)");
  EXPECT_THAT(ErrorOf("{mode: realtime, rate_hz: 25, source: head.command}", topic),
              HasSubstr("head.yaml:1: clock.source: 'source' is for mode simulated"));
  EXPECT_THAT(ErrorOf("{mode: simulated, source: head}", topic),
              HasSubstr("head.yaml:1: clock.source: expected <component>.<input>"));
  EXPECT_THAT(ErrorOf("{mode: simulated, source: haed.command}", topic),
              HasSubstr("head.yaml:1: clock.source: unknown component 'haed' in 'haed.command'; "
                        "components: head"));
  EXPECT_THAT(ErrorOf("{mode: simulated, source: head.comand}", topic),
              HasSubstr("clock.source: component 'head' has no input 'comand' connected"));
  // Only a topic's messages carry a sender's stamps.
  const std::string local =
      "clock: {mode: simulated, steps: 1, source: head.command}\n"
      "scene: " +
      kScene +
      "\n"
      "transport: {domain: 185}\n"
      "components:\n"
      "  - name: fixation\n"
      "    type: control.fixation\n"
      "    inputs: {target: {topic: target}}\n"
      "  - name: head\n"
      "    type: sim.head\n"
      "    inputs: {command: fixation.command}\n";
  try {
    runtime::Pipeline::LoadString(local, "local.yaml");
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_THAT(e.what(), HasSubstr("local.yaml:1: clock.source: input 'head.command' reads "
                                    "'fixation.command', not a topic"));
  }
}

TEST_F(PipelineTopics, BadTopicConnectionsNameFileLineAndKey) {
  const auto ErrorOf = [](const std::string& text, const runtime::ComponentRegistry& registry =
                                                       runtime::ComponentRegistry::Global()) {
    try {
      runtime::Pipeline::LoadString(text, "head.yaml", registry);
    } catch (const FileError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_THAT(ErrorOf(HeadPipeline(182, "{topic: head/command, qos: fast}")),
              HasSubstr("head.yaml:8: components[0].inputs.command: head.command.qos: unknown QoS "
                        "profile 'fast'"));
  EXPECT_THAT(ErrorOf(HeadPipeline(182, "{topic: 'head command'}")),
              HasSubstr("head.yaml:8: components[0].inputs.command: topic 'head command': "
                        "character ' ' is not allowed"));
  EXPECT_THAT(
      ErrorOf(HeadPipeline(182, "{topic: head/command, wait: 3}")),
      HasSubstr("head.command: unknown key 'wait'; expected lockstep, qos, start_wait_s, targets, "
                "tf, wait_s"));
  EXPECT_THAT(ErrorOf(HeadPipeline(182, "{topic: head/command, lockstep: 1}")),
              HasSubstr("head.yaml:8: components[0].inputs.command: head.command.lockstep: "
                        "expected true or false, got 1"));
  EXPECT_THAT(ErrorOf(HeadPipeline(182, "{topic: head/command, targets: head/goal}")),
              HasSubstr("head.command.targets: only joint states have targets; this port "
                        "carries head.command"));
  std::string joints = HeadPipeline(182, "{topic: head/command}");
  joints.replace(joints.find("joints: joint_states"), 20,
                 "joints: {topic: joint_states, lockstep: true}");
  EXPECT_THAT(ErrorOf(joints),
              HasSubstr("head.yaml:9: components.head.outputs.joints: head.joints.lockstep: only "
                        "head commands (head.command) mark steps; this port carries head.joints"));
  EXPECT_THAT(ErrorOf(HeadPipeline(300, "{topic: head/command}")),
              HasSubstr("transport.domain: expected an integer 0..232, got 300"));
  // A program without a topic transport says so.
  runtime::ComponentRegistry plain;
  components::RegisterComponents(plain);
  EXPECT_THAT(ErrorOf(HeadPipeline(182, "{topic: head/command}"), plain),
              HasSubstr("reads the topic 'head/command', but this program has no topic "
                        "transport (DDS)"));
}

// A lockstep writer answers every step of its pipeline (runtime::Pipeline::EndStep): with the
// step's command when the component sent one, else an empty JointState stamped with the step's
// time, so that the robot in lockstep knows the step is done.
TEST_F(PipelineTopics, LockstepCommandsAnswerEveryStep) {
  constexpr int kDomain = 186;
  const std::string text =
      "clock: {mode: simulated, step: 0.04, steps: 3}\n"
      "scene: " +
      kScene +
      "\n"
      "transport: {domain: 186, namespace: /saccade}\n"
      "components:\n"
      "  - name: fixation\n"
      "    type: control.fixation\n"
      "    inputs: {target: {topic: target, wait_s: 0.5, start_wait_s: 10}}\n"
      "    outputs: {command: {topic: head/command, lockstep: true}}\n";
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(text, "perception.yaml");
  Raw raw(RawParticipant(kDomain));
  Raw commands(RawReader(raw.get(), &ref_sensor_msgs_msg_dds__JointState__desc,
                         "rt/saccade/head/command", 10));
  Raw target(
      RawWriter(raw.get(), &ref_geometry_msgs_msg_dds__PointStamped__desc, "rt/saccade/target"));
  ASSERT_TRUE(WaitWriterMatched(target.get()));
  ASSERT_TRUE(WaitReaderMatched(commands.get()));
  // One target, before the first step: step 0 commands the head; steps 1 and 2 have nothing.
  ref_geometry_msgs_msg_dds__PointStamped_ point{};
  point.header.frame_id = const_cast<char*>("world");
  point.point = {2.0, 0.3, 1.0};
  ASSERT_EQ(dds_write(target.get(), &point), DDS_RETCODE_OK);
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline);
  ASSERT_EQ(summary.errors_total, 0) << summary.FullReport();
  ASSERT_EQ(summary.steps, 3);

  std::vector<std::pair<uint32_t, uint32_t>> got;  // (joints named, stamp in ns)
  ref_sensor_msgs_msg_dds__JointState_ sample{};
  while (TakeSample(commands.get(), &sample, 1.0)) {
    got.emplace_back(sample.name._length, sample.header.stamp.nanosec);
    dds_sample_free(&sample, &ref_sensor_msgs_msg_dds__JointState__desc, DDS_FREE_CONTENTS);
    sample = {};  // freed contents: Cyclone would reuse the pointers
  }
  EXPECT_THAT(got, ::testing::ElementsAre(::testing::Pair(4u, 0u), ::testing::Pair(0u, 40000000u),
                                          ::testing::Pair(0u, 80000000u)));
}

// Stands in for mapping.world_map (issue 44): a map of `step + 1` voxels and one inhibited
// place each step.
class MapSource final : public runtime::Component {
 public:
  MapSource() : map_(AddOutput<components::MapMessage>("map")) {}
  void Step(const runtime::StepContext& context) override {
    components::MapMessage m;
    m.time = context.time;
    m.frame_index = context.step;
    m.resolution_m = 0.05;
    for (int64_t i = 0; i <= context.step; ++i) m.occupied_W.emplace_back(0.05 * i, 1.0, 0.5);
    m.inhibited = {{{1.0, 0.0, 1.0}, 0.2, 1.0}};
    map_.Emit(m);
  }

 private:
  runtime::Output<components::MapMessage>& map_;
};

// `map: {topic: map}` on a component's mapping.map output publishes sensor_msgs/PointCloud2 on
// /saccade/map and the inhibited places on /saccade/map/inhibited, latched: a viewer that comes
// after the run still gets the newest map.
TEST_F(PipelineTopics, MapOutputPublishesPointCloud2AndItsInhibitedPlaces) {
  constexpr int kDomain = 188;
  runtime::ComponentRegistry registry;
  components::RegisterComponents(registry);
  RegisterDdsTransport(registry);
  registry.Register<MapSource>("test.map_source");
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(
      "clock: {mode: simulated, step: 0.04, steps: 3}\n"
      "transport: {domain: 188, namespace: /saccade, clock: \"\"}\n"
      "components:\n"
      "  - name: mapper\n"
      "    type: test.map_source\n"
      "    outputs: {map: {topic: map}}\n",
      "map.yaml", registry);
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline);
  ASSERT_EQ(summary.errors_total, 0) << summary.FullReport();

  Raw raw(RawParticipant(kDomain));
  const auto Latest = [&](const char* topic) {
    Raw reader(RawReader(raw.get(), &ref_sensor_msgs_msg_dds__PointCloud2__desc, topic, 1,
                         /*transient_local=*/true));
    ref_sensor_msgs_msg_dds__PointCloud2_ cloud{};
    std::pair<uint32_t, std::string> got{0, "(nothing)"};
    if (TakeSample(reader.get(), &cloud)) {
      got = {cloud.width, cloud.header.frame_id};
      dds_sample_free(&cloud, &ref_sensor_msgs_msg_dds__PointCloud2__desc, DDS_FREE_CONTENTS);
    }
    return got;
  };
  // The last step's map: 3 voxels; its one inhibited place.
  EXPECT_EQ(Latest("rt/saccade/map"), std::make_pair(3u, std::string("world")));
  EXPECT_EQ(Latest("rt/saccade/map/inhibited"), std::make_pair(1u, std::string("world")));
}

// sim.cameras' raw mosaic (`raw: true`) on a topic of its own: sensor_msgs/Image with ROS's Bayer
// encoding, the mosaic's bytes, beside the demosaiced image on image_raw.
TEST_F(PipelineTopics, RawMosaicOutputPublishesBayerImages) {
  constexpr int kDomain = 190;
  const std::string scene = (saccade::testing_helpers::ScratchDir() / "bayer.yaml").string();
  std::ofstream(scene) << "lights: [{type: ambient, intensity: 1}]\n"
                          "ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2]}\n"
                          "cameras:\n"
                          "  - name: eye\n"
                          "    calibration: {width: 64, height: 48, fx: 50, fy: 50}\n"
                          "    look_at: {eye: [0, 0, 1], target: [2, 0, 0]}\n"
                          "    sensor: {color: {cfa: rggb}}\n";
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(
      "clock: {mode: simulated, step: 0.04, steps: 2}\n"
      "transport: {domain: 190, namespace: /saccade, clock: \"\"}\n"
      "components:\n"
      "  - name: cams\n"
      "    type: sim.cameras\n"
      "    params: {scene: " +
          scene +
          ", cameras: [eye], raw: true}\n"
          "    outputs:\n"
          "      eye: eye/image_raw\n"
          "      eye_raw: {topic: eye/raw/image_raw, tf: \"\", compressed: \"\"}\n",
      "raw.yaml");
  std::map<int64_t, std::shared_ptr<const Image>> sent;  // by stamp, ns
  for (const auto& c : pipeline.components()) {
    if (c->name() != "cams") continue;
    auto* raw = dynamic_cast<runtime::Output<runtime::ImageMessage>*>(c->FindOutput("eye_raw"));
    ASSERT_NE(raw, nullptr);
    raw->signal().Connect([&](const runtime::ImageMessage& m) {
      sent[std::llround(m.image->metadata().time * 1e9)] = m.image;
    });
  }
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline);
  ASSERT_EQ(summary.errors_total, 0) << summary.FullReport();
  ASSERT_EQ(sent.size(), 2u);

  // The writer keeps its last 2 images for a reader that comes later (transient local; Cyclone
  // kept 1 until the durability service's history was set): each one taken is the mosaic sent
  // at its stamp, the newest the last step's.
  Raw participant(RawParticipant(kDomain));
  Raw reader(RawReader(participant.get(), &ref_sensor_msgs_msg_dds__Image__desc,
                       "rt/saccade/eye/raw/image_raw", 2, /*transient_local=*/true));
  int64_t newest = -1;
  int taken = 0;
  ref_sensor_msgs_msg_dds__Image_ got{};
  for (double wait_s = 10.0; TakeSample(reader.get(), &got, wait_s); wait_s = 0.5) {
    const int64_t stamp = int64_t{got.header.stamp.sec} * 1'000'000'000 + got.header.stamp.nanosec;
    ASSERT_TRUE(sent.count(stamp)) << stamp;
    newest = std::max(newest, stamp);
    const Image& image = *sent[stamp];
    EXPECT_STREQ(got.encoding, "bayer_rggb8");
    EXPECT_STREQ(got.header.frame_id, "eye_optical");
    EXPECT_EQ(got.width, 64u);
    EXPECT_EQ(got.height, 48u);
    EXPECT_EQ(got.step, 64u);
    ASSERT_EQ(got.data._length, image.size_bytes());
    EXPECT_EQ(std::memcmp(got.data._buffer, image.data(), image.size_bytes()), 0);
    dds_sample_free(&got, &ref_sensor_msgs_msg_dds__Image__desc, DDS_FREE_CONTENTS);
    got = {};
    ++taken;
  }
  EXPECT_EQ(taken, 2) << "a late reader gets both images the writer keeps";
  EXPECT_EQ(newest, sent.rbegin()->first);
}

TEST_F(PipelineTopics, OutputsMustExistAndHaveARosForm) {
  const std::string base =
      "clock: {mode: simulated, step: 0.04, steps: 1}\n"
      "scene: " +
      kScene +
      "\n"
      "transport: {domain: 183}\n"
      "components:\n"
      "  - name: head\n"
      "    type: sim.head\n";
  try {
    runtime::Pipeline::LoadString(base + "    outputs: {jionts: joint_states}\n", "h.yaml");
    FAIL() << "no error";
  } catch (const FileError& e) {
    EXPECT_THAT(e.what(), HasSubstr("h.yaml:7: components.head.outputs.jionts: component 'head' "
                                    "(sim.head) has no output 'jionts'; its outputs: joints"));
  }
}

}  // namespace
}  // namespace saccade::dds
