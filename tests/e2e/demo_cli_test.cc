// `saccade demo` used as a person or a script would: the loop's report, the recording in real
// formats, and the errors for bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>
#include <regex>
#include <sstream>
#include <string>

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

// `name` in the test's scratch folder, absent.
fs::path TempDir(const std::string& name) {
  const fs::path dir = saccade::testing_helpers::ScratchDir() / name;
  fs::remove_all(dir);
  return dir;
}

// The JSON report (the same as the recording's summary.json) and the recording itself.
TEST(DemoCli, FixatesTheFaceRejectsTheCatAndRecordsAVideoThatOpenCvReads) {
  const fs::path out = TempDir("record");
  const CommandRun run =
      Saccade("demo --scene " + kTwoPictures + " --duration 4 --json --record " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const json report = json::parse(run.output);
  EXPECT_EQ(report["faces"], 1);
  EXPECT_EQ(report["faces_fixated"], 1);
  ASSERT_FALSE(report["fixations"].empty());
  const json& f = report["fixations"][0];
  EXPECT_EQ(f["object"], "astronaut");
  EXPECT_LT(f["error_3d_m"].get<double>(), 0.05);
  EXPECT_LT(f["eye_error_deg"]["left"].get<double>(), 0.5);
  EXPECT_LT(f["eye_error_deg"]["right"].get<double>(), 0.5);
  EXPECT_GT(f["time_to_fixate_s"].get<double>(), 0.0);
  ASSERT_EQ(report["decoys"].size(), 1u);
  EXPECT_EQ(report["decoys"][0]["name"], "chelsea");
  EXPECT_EQ(report["decoys"][0]["rejected"], true);
  EXPECT_GT(report["latency_ms"]["capture_to_command"]["median"].get<double>(), 0.0);
  EXPECT_LT(report["overhead_share"].get<double>(), 0.01);

  // The recording: one JPEG per step, a video with as many frames, a PNG of the fixation.
  std::ifstream summary_file(out / "summary.json");
  const json summary = json::parse(summary_file);
  EXPECT_EQ(summary["faces_fixated"], 1);
  const int64_t steps = summary["steps"];
  int64_t jpegs = 0;
  for (const auto& e : fs::directory_iterator(out / "frames"))
    jpegs += e.path().extension() == ".jpg";
  EXPECT_EQ(jpegs, steps);
  EXPECT_TRUE(fs::exists(out / "fixation_1_astronaut.png"));
  // OpenCV's own MJPEG reader: no FFmpeg or GStreamer needed to read what the demo wrote.
  cv::VideoCapture video((out / "demo.avi").string(), cv::CAP_OPENCV_MJPEG);
  ASSERT_TRUE(video.isOpened());
  int64_t frames = 0;
  int width = 0;
  for (cv::Mat frame; video.read(frame); ++frames) width = frame.cols;
  EXPECT_EQ(frames, steps);
  EXPECT_EQ(width, 1024);  // both eyes side by side at half size

  // The same folder again without --force: refused, and the recording is kept.
  const CommandRun again =
      Saccade("demo --scene " + kTwoPictures + " --duration 1 --record " + out.string());
  EXPECT_EQ(again.status, 1);
  EXPECT_THAT(again.output, HasSubstr("already holds a recording; pass --force"));
  std::ifstream kept(out / "summary.json");
  EXPECT_EQ(json::parse(kept)["steps"], steps);
}

TEST(DemoCli, ExitsNonZeroWhenNoFaceIsFixated) {
  // Two steps: the head cannot have reached any face yet.
  const CommandRun run = Saccade("demo --scene " + kTwoPictures + " --duration 0.08");
  EXPECT_EQ(run.status, 3) << run.output;
  EXPECT_THAT(run.output, HasSubstr("0 of 1 faces fixated"));
  EXPECT_THAT(run.output, HasSubstr("no face was fixated"));
}

TEST(DemoCli, ABadPipelineNamesTheFileLineAndWhatIsKnown) {
  const fs::path dir = TempDir("pipelines");
  fs::create_directories(dir);
  const fs::path file = dir / "bad.yaml";
  std::ofstream(file) << "clock: {mode: simulated, step: 0.04}\n"
                         "components:\n"
                         "  - name: cameras\n"
                         "    type: sim.camera\n";
  const CommandRun run = Saccade("demo --pipeline " + file.string());
  EXPECT_EQ(run.status, 1);
  EXPECT_THAT(run.output, HasSubstr(file.string() + ":4: components[0].type: unknown component "
                                                    "type 'sim.camera'"));
  EXPECT_THAT(run.output, HasSubstr("sim.cameras"));  // the known types are listed
}

// A component that fails mid-run: reported with its name and step, the run stops cleanly, and
// what was recorded up to then is kept whole; --keep-going carries on past it.
TEST(DemoCli, AFailingComponentIsNamedAndTheRecordingIsKept) {
  const fs::path dir = TempDir("fault");
  fs::create_directories(dir);
  std::ifstream demo(kSource + "/pipelines/demo.yaml");
  std::stringstream yaml;
  yaml << demo.rdbuf()
       << "  - {name: fault, type: debug.fault, params: {at_step: 5, message: 'the motor "
          "driver went away'}}\n";
  // The copy lives in another folder: its hardware file, by its absolute path.
  std::string text = yaml.str();
  const std::string line = "hardware: hardware/simulator.yaml";
  ASSERT_NE(text.find(line), std::string::npos);
  text.replace(text.find(line), line.size(),
               "hardware: " + kSource + "/pipelines/hardware/simulator.yaml");
  std::ofstream(dir / "faulty.yaml") << text;
  const fs::path out = dir / "record";
  // The copy is in another folder: its `hardware:` line is given on the command line.
  const CommandRun run =
      Saccade("demo --pipeline " + (dir / "faulty.yaml").string() + " --hardware " + kSource +
              "/pipelines/hardware/simulator.yaml" + " --scene " + kTwoPictures +
              " --duration 4 --record " + out.string());
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_THAT(run.output,
              HasSubstr("component 'fault' failed at step 5: the motor driver went away"));
  std::ifstream summary_file(out / "summary.json");
  const json summary = json::parse(summary_file);
  EXPECT_EQ(summary["steps"], 6);  // steps 0..5, the failing one included
  ASSERT_EQ(summary["errors"].size(), 1u);
  int64_t jpegs = 0;
  for (const auto& e : fs::directory_iterator(out / "frames"))
    jpegs += e.path().extension() == ".jpg";
  EXPECT_EQ(jpegs, 6);
  cv::VideoCapture video((out / "demo.avi").string(), cv::CAP_OPENCV_MJPEG);
  int64_t frames = 0;
  for (cv::Mat frame; video.read(frame);) ++frames;
  EXPECT_EQ(frames, 6);  // the video was closed properly

  const CommandRun going = Saccade("demo --pipeline " + (dir / "faulty.yaml").string() +
                                   " --scene " + kTwoPictures + " --duration 4 --keep-going");
  EXPECT_EQ(going.status, 0) << going.output;
  EXPECT_THAT(going.output, HasSubstr("1 of 1 faces fixated"));
  // Over the fixation, each eye's largest error from the true face centre.
  std::smatch dwell;
  ASSERT_TRUE(std::regex_search(
      going.output, dwell,
      std::regex(
          R"(eye axis error over each fixation, largest:\n  astronaut +L ([0-9.]+) R ([0-9.]+) deg)")))
      << going.output;
  EXPECT_LT(std::stod(dwell[1]), 0.5);
  EXPECT_LT(std::stod(dwell[2]), 0.5);
}

// Real time: ticks on the wall clock at the pipeline's 25 Hz (or slower, when a step takes
// longer), the motors moving by the wall time that passed.
TEST(DemoCli, RunsInRealTime) {
  const CommandRun run =
      Saccade("demo --scene " + kTwoPictures + " --duration 0.4 --realtime --json");
  EXPECT_TRUE(run.status == 0 || run.status == 3) << run.output;
  // The report, without the line on stderr when no face was fixated.
  const std::size_t begin = run.output.find('{'), end = run.output.rfind('}');
  ASSERT_NE(begin, std::string::npos) << run.output;
  const json report = json::parse(run.output.substr(begin, end - begin + 1));
  // At most 10 ticks (fewer when every face was done sooner: time is the wall's).
  const int64_t steps = report["steps"];
  EXPECT_GE(steps, 1);
  EXPECT_LE(steps, 10);
  // Tick k starts no sooner than k periods after the first, and the clock is the wall's:
  // never ahead of the run's wall time.
  const double time = report["sim_time_s"];
  EXPECT_GE(time, 0.04 * steps - 1e-9);
  EXPECT_LE(time, report["wall_s"].get<double>() + 0.04);
  // The figures issue 14 is about follow from the counts: at most 1 when real time keeps pace.
  EXPECT_DOUBLE_EQ(report["real_time_factor"].get<double>(), time / report["wall_s"].get<double>());
  EXPECT_DOUBLE_EQ(report["steps_per_second"].get<double>(),
                   steps / report["wall_s"].get<double>());
  EXPECT_LE(report["real_time_factor"].get<double>(), 1.0 + 0.04 / report["wall_s"].get<double>());
  // --duration is wall seconds here: no step starts at or after 0.4 s, however slow the steps.
  EXPECT_LT(time - 0.04, 0.4);
  // The steps that overran their 40 ms are counted, and only on the real-time clock.
  ASSERT_TRUE(report["overruns"].is_number_integer()) << report;
  EXPECT_GE(report["overruns"].get<int64_t>(), 0);
  EXPECT_LE(report["overruns"].get<int64_t>(), steps);
  const CommandRun simulated = Saccade("demo --scene " + kTwoPictures + " --duration 0.08 --json");
  const std::size_t b = simulated.output.find('{'), e = simulated.output.rfind('}');
  ASSERT_NE(b, std::string::npos) << simulated.output;
  EXPECT_TRUE(json::parse(simulated.output.substr(b, e - b + 1))["overruns"].is_null());
}

// Any head (issue 42): the demo's figures with the humanoid head (three neck joints, an eye tilt,
// two eye pans) and the pan-tilt head whose eyes share one vergence motor (a mimic joint): every
// portrait fixated, the cat never, 3D error <= 15 mm at 1-3 m and eyes within 0.15 deg over each
// fixation, as with POPEYE.
void ExpectTheDemoOn(const std::string& head, const std::string& scene, double max_eye_deg) {
  SCOPED_TRACE(head + " on " + scene);
  const CommandRun run = Saccade("demo --head " + kSource + "/robots/" + head + " --scene " +
                                 kSource + "/scenes/" + scene + " --duration 8 --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const json report = json::parse(run.output);
  EXPECT_EQ(report["faces"], 3);
  EXPECT_EQ(report["faces_fixated"], 3) << report["fixations"].dump();
  for (const json& f : report["fixations"]) {
    if (!f["fixated"].get<bool>()) continue;
    EXPECT_TRUE(f["is_face"].get<bool>()) << f.dump();
    const double d = f["distance_m"].get<double>();
    EXPECT_TRUE(d >= 1.0 && d <= 3.1) << f.dump();
    EXPECT_LE(f["error_3d_m"].get<double>(), 0.015) << f.dump();
    EXPECT_LE(f["eye_error_deg"]["left"].get<double>(), max_eye_deg) << f.dump();
    EXPECT_LE(f["eye_error_deg"]["right"].get<double>(), max_eye_deg) << f.dump();
    EXPECT_LE(f["dwell_eye_error_deg"]["left_max"].get<double>(), max_eye_deg) << f.dump();
    EXPECT_LE(f["dwell_eye_error_deg"]["right_max"].get<double>(), max_eye_deg) << f.dump();
  }
  ASSERT_EQ(report["decoys"].size(), 1u);
  EXPECT_EQ(report["decoys"][0]["fixated"], false);
}

TEST(DemoCli, AnyHeadFixatesEveryPortraitNeverTheCat) {
  ExpectTheDemoOn("humanoid.yaml", "portraits.yaml", 0.15);
  ExpectTheDemoOn("pan_tilt_vergence.yaml", "portraits.yaml", 0.15);
}

// The moving portraits: pursuit keeps the eyes on the faces. POPEYE's own largest error there
// is 0.21 deg (the pursuit's lag as a fixation begins); the same bound for every head.
TEST(DemoCli, AnyHeadPursuesTheMovingPortraits) {
  ExpectTheDemoOn("humanoid.yaml", "portraits_moving.yaml", 0.25);
  ExpectTheDemoOn("pan_tilt_vergence.yaml", "portraits_moving.yaml", 0.25);
}

// --head names what is wrong: a file that is not a head, a scene without a robot to replace.
TEST(DemoCli, ABadHeadIsNamed) {
  const fs::path dir = TempDir("bad_head");
  fs::create_directories(dir);
  {
    std::ofstream(dir / "not_a_head.yaml") << "name: x\nwheels: 4\n";
    std::ofstream(dir / "no_robot.yaml") << "objects: []\n";
  }
  const CommandRun bad = Saccade("demo --head " + (dir / "not_a_head.yaml").string() + " --scene " +
                                 kTwoPictures + " --duration 0.08");
  EXPECT_EQ(bad.status, 1) << bad.output;
  EXPECT_THAT(bad.output, HasSubstr("not_a_head.yaml"));
  EXPECT_THAT(bad.output, HasSubstr("wheels"));
  const CommandRun no_robot =
      Saccade("render --head " + kSource + "/robots/humanoid.yaml --scene " +
              (dir / "no_robot.yaml").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(no_robot.status, 1) << no_robot.output;
  EXPECT_THAT(no_robot.output, HasSubstr("no robot"));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(DemoCli, ListsItsComponents) {
  const CommandRun run = Saccade("demo --list-components");
  EXPECT_EQ(run.status, 0);
  for (const char* type :
       {"sim.cameras", "sim.head", "vision.face_detector", "vision.camshift", "vision.triangulate",
        "control.fixation", "vision.undistort", "debug.fault"}) {
    EXPECT_THAT(run.output, HasSubstr(type));
  }
}

}  // namespace
