// The demo's pipeline, unchanged, on other hardware (issue 7): the head on the emulated
// Dynamixel bus (saccade-servo-emulator, a separate process on a pseudo-terminal), in mirror
// mode, with emulated servo faults, and the eye cameras replaced by OpenCV's recorded stereo
// pair -- each through a hardware file, as a user would switch them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "e2e/run_saccade.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using saccade::e2e::CommandRun;
using saccade::e2e::Saccade;
using ::testing::HasSubstr;

const std::string kSource = SACCADE_SOURCE_DIR;
const std::string kTwoPictures = kSource + "/scenes/astronaut_and_cat.yaml";
// Three faces to fixate in turn: the loop runs until the third fixation (about 3.4 s of
// simulated time, 86 steps: 6 s of wall time on the 2-core development machine, at most 3.4 s
// at camera rate), long enough for a fault timed 1.5 s after the host's first instruction
// (the emulator's clock for faults, whatever the start-up took) to strike mid-run.
const std::string kPortraits = kSource + "/scenes/portraits.yaml";

fs::path TempDir(const std::string& name) {
  return saccade::testing_helpers::FreshScratchDir(name);
}

// saccade-servo-emulator in the background, for the length of a test.
class Emulator {
 public:
  // `args` besides --link; returns once it has printed its first line.
  Emulator(const fs::path& link, std::vector<std::string> args)
      : process_([&] {
          args.insert(args.begin(), {SACCADE_SERVO_EMULATOR, "--link", link.string()});
          return args;
        }()) {
    const std::optional<std::string> line = process_.ReadLine();
    if (!line) ADD_FAILURE() << "saccade-servo-emulator printed nothing";
    first_line_ = line.value_or("");
  }
  const std::string& first_line() const { return first_line_; }

 private:
  saccade::e2e::BackgroundProcess process_;
  std::string first_line_;
};

// A hardware file: simulated cameras on `scene`, the head on the bus at `port`.
fs::path ServoHardware(const fs::path& dir, const fs::path& port, bool mirror,
                       const std::string& scene = kTwoPictures) {
  const fs::path file = dir / "servos.yaml";
  std::ofstream(file) << "scene: " << scene
                      << "\n"
                         "components:\n"
                         "  cameras:\n"
                         "    type: sim.cameras\n"
                         "  head:\n"
                         "    type: hw.head\n"
                         "    params: {driver: dynamixel, port: "
                      << port.string()
                      << ", watchdog_s: 1.0, mirror: " << (mirror ? "true" : "false") << "}\n";
  return file;
}

json Summary(const fs::path& record) {
  std::ifstream in(record / "summary.json");
  return json::parse(in);
}

TEST(HardwareCli, TheDemoFixatesTheFaceWithTheHeadOnTheEmulatedServoBus) {
  const fs::path dir = TempDir("servos");
  Emulator emulator(dir / "bus", {});
  ASSERT_THAT(emulator.first_line(), HasSubstr("serving servos 1,2,3,4"));
  const CommandRun run =
      Saccade("demo --hardware " + ServoHardware(dir, dir / "bus", false).string() +
              " --duration 3 --record " + (dir / "rec").string());
  ASSERT_EQ(run.status, 0) << run.output;
  const json s = Summary(dir / "rec");
  EXPECT_EQ(s["faces_fixated"], 1);
  const json& f = s["fixations"][0];
  EXPECT_EQ(f["object"], "astronaut");
  EXPECT_LT(f["error_3d_m"].get<double>(), 0.05);
  EXPECT_LT(f["eye_error_deg"]["left"].get<double>(), 0.5);
  EXPECT_LT(f["eye_error_deg"]["right"].get<double>(), 0.5);
  const json& head = s["head"];
  EXPECT_THAT(head["driver"].get<std::string>(),
              HasSubstr("dynamixel on " + (dir / "bus").string()));
  EXPECT_GT(head["commands"].get<int>(), 10);
  EXPECT_EQ(head["rejected_commands"], 0);
  EXPECT_EQ(head["fault"], "");
  // The servos moved the head off its home: the picture is not straight ahead.
  EXPECT_GT(std::abs(head["positions"]["pan"].get<double>()) +
                std::abs(head["positions"]["tilt"].get<double>()),
            0.01);
  EXPECT_THAT(run.output, HasSubstr("head: dynamixel on"));
}

// Any head on the bus (issue 42): the humanoid head's six joints on six servos, mapped by joint
// name from its head file (robots/humanoid.yaml: ids 1-6); the loop fixates through them. A bus
// that lacks one of its servos is refused at start, naming the servo and its joint.
TEST(HardwareCli, TheHumanoidHeadFixatesOnSixEmulatedServos) {
  const fs::path dir = TempDir("six_servos");
  const std::string humanoid = kSource + "/robots/humanoid.yaml";
  {
    Emulator emulator(dir / "bus", {"--ids", "1,2,3,4,5,6"});
    ASSERT_THAT(emulator.first_line(), HasSubstr("serving servos 1,2,3,4,5,6"));
    const CommandRun run = Saccade("demo --head " + humanoid + " --hardware " +
                                   ServoHardware(dir, dir / "bus", false).string() +
                                   " --duration 3 --record " + (dir / "rec").string());
    ASSERT_EQ(run.status, 0) << run.output;
    const json s = Summary(dir / "rec");
    EXPECT_EQ(s["faces_fixated"], 1);
    const json& f = s["fixations"][0];
    EXPECT_LT(f["error_3d_m"].get<double>(), 0.015);
    EXPECT_LT(f["eye_error_deg"]["left"].get<double>(), 0.5);
    EXPECT_LT(f["eye_error_deg"]["right"].get<double>(), 0.5);
    const json& head = s["head"];
    EXPECT_EQ(head["fault"], "");
    EXPECT_EQ(head["rejected_commands"], 0);
    EXPECT_GT(head["commands"].get<int>(), 10);
    // The servos' own positions, by the humanoid's joint names; the eyes turned to the face
    // (the picture is off to the left), each servo at its target within a few ticks.
    ASSERT_EQ(head["positions"].size(), 6u) << head.dump();
    for (const char* joint :
         {"neck_pitch", "neck_roll", "neck_yaw", "eye_tilt", "left_eye_pan", "right_eye_pan"}) {
      ASSERT_TRUE(head["positions"].contains(joint)) << joint << " " << head.dump();
      EXPECT_NEAR(head["positions"][joint].get<double>(), head["targets"][joint].get<double>(),
                  0.01)
          << joint;
    }
    EXPECT_GT(head["positions"]["left_eye_pan"].get<double>(), 0.02);
    EXPECT_GT(head["positions"]["right_eye_pan"].get<double>(), 0.02);
    EXPECT_EQ(head["positions"]["neck_roll"].get<double>(), 0.0);  // held by the fixation rule
  }
  Emulator four(dir / "bus4", {});  // servos 1-4 only
  const CommandRun missing =
      Saccade("demo --head " + humanoid + " --hardware " +
              ServoHardware(dir, dir / "bus4", false).string() + " --duration 1");
  EXPECT_EQ(missing.status, 1) << missing.output;
  EXPECT_THAT(missing.output, HasSubstr("servo 5 (left_eye_pan) does not answer"));
}

TEST(HardwareCli, InMirrorModeTheServosFollowTheVirtualHead) {
  const fs::path dir = TempDir("mirror");
  Emulator emulator(dir / "bus", {});
  const CommandRun run =
      Saccade("demo --hardware " + ServoHardware(dir, dir / "bus", true).string() +
              " --duration 3 --record " + (dir / "rec").string());
  ASSERT_EQ(run.status, 0) << run.output;
  const json s = Summary(dir / "rec");
  EXPECT_EQ(s["faces_fixated"], 1);
  const json& head = s["head"];
  EXPECT_EQ(head["mirror"], true);
  EXPECT_EQ(head["fault"], "");
  // Sent: the virtual head's joints; measured: where the servos are. At the end of a
  // fixation they agree to a servo tick or two (0.088 deg each).
  for (const char* joint : {"pan", "tilt", "left", "right"}) {
    EXPECT_NEAR(head["positions"][joint].get<double>(), head["targets"][joint].get<double>(), 0.004)
        << joint;
  }
  EXPECT_GT(std::abs(head["targets"]["pan"].get<double>()), 0.01);
}

TEST(HardwareCli, AServoOverloadIsReportedAndTheLoopGoesOnWithTheHeadHeld) {
  const fs::path dir = TempDir("overload");
  Emulator emulator(dir / "bus", {"--overload", "2@1.5"});
  const CommandRun run =
      Saccade("demo --hardware " + ServoHardware(dir, dir / "bus", false, kPortraits).string() +
              " --duration 4 --record " + (dir / "rec").string());
  EXPECT_NE(run.status, 1) << "the fault stopped the loop:\n" << run.output;
  EXPECT_THAT(run.output, HasSubstr("FAULT: servo 2 (tilt): overload"));
  const json s = Summary(dir / "rec");
  const json& head = s["head"];
  EXPECT_THAT(head["fault"].get<std::string>(), HasSubstr("servo 2 (tilt): overload"));
  EXPECT_GT(head["rejected_commands"].get<int>(), 0) << "commands after the fault were sent";
  EXPECT_TRUE(s["errors"].empty()) << s["errors"].dump();
}

TEST(HardwareCli, AServoThatStopsAnsweringIsReported) {
  const fs::path dir = TempDir("silent");
  Emulator emulator(dir / "bus", {"--silent", "3@1.5"});
  const CommandRun run =
      Saccade("demo --hardware " + ServoHardware(dir, dir / "bus", false, kPortraits).string() +
              " --duration 4 --record " + (dir / "rec").string());
  EXPECT_NE(run.status, 1) << run.output;
  const json s = Summary(dir / "rec");
  const std::string fault = s["head"]["fault"].get<std::string>();
  EXPECT_THAT(fault, HasSubstr("servo 3"));
  EXPECT_THAT(fault, HasSubstr("no status packet"));
  EXPECT_GT(s["head"]["rejected_commands"].get<int>(), 0);
}

TEST(HardwareCli, WithoutTheBusTheErrorNamesThePort) {
  const fs::path dir = TempDir("nobus");
  const CommandRun run = Saccade(
      "demo --hardware " + ServoHardware(dir, dir / "no-bus", false).string() + " --duration 1");
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr((dir / "no-bus").string()));
  EXPECT_THAT(run.output, HasSubstr("head"));
}

TEST(HardwareCli, TheDemoRunsOnOpenCvsRecordedStereoPair) {
  const fs::path dir = TempDir("recorded");
  const CommandRun run =
      Saccade("demo --hardware " + kSource + "/pipelines/hardware/recorded_cameras.yaml" +
              " --duration 1 --record " + (dir / "rec").string());
  // Chessboards: the loop runs, finds no face, and says so.
  EXPECT_EQ(run.status, 3) << run.output;
  EXPECT_THAT(run.output, HasSubstr("real cameras (hw.cameras): no ground truth"));
  const json s = Summary(dir / "rec");
  EXPECT_EQ(s["ground_truth"], false);
  EXPECT_EQ(s["cameras"]["pairs"], 25);
  EXPECT_EQ(s["cameras"]["dropped_left"], 0);
  EXPECT_EQ(s["steps"], 25);
  EXPECT_TRUE(s["errors"].empty()) << s["errors"].dump();
  EXPECT_EQ(s["record"]["frames"], 25);
}

}  // namespace
