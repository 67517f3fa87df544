// `saccade render` used as a person would: files on disk, in real formats, read back by OpenCV.

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <thread>

#include "e2e/run_saccade.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

using saccade::e2e::CommandRun;
using saccade::e2e::Saccade;

const std::string kScene = std::string(SACCADE_SOURCE_DIR) + "/scenes/portraits.yaml";

class RenderCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("saccade_render_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::vector<json> Index(const fs::path& out) const {
    std::vector<json> lines;
    std::ifstream in(out / "frames.jsonl");
    for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
    return lines;
  }
  fs::path dir_;
};

TEST_F(RenderCli, WritesFramesCalibrationsAndMetadata) {
  const fs::path out = dir_ / "out";
  const CommandRun run =
      Saccade("render --scene " + kScene + " --frames 3 --fps 10 --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const std::vector<json> index = Index(out);
  ASSERT_EQ(index.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(index[i]["frame"].get<int>(), i);
    EXPECT_DOUBLE_EQ(index[i]["time"].get<double>(), i / 10.0);
    for (const char* camera : {"left", "right"}) {
      const json& c = index[i]["cameras"][camera];
      ASSERT_FALSE(c.is_null()) << camera;
      const cv::Mat image =
          cv::imread((out / c["file"].get<std::string>()).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(image.empty()) << c["file"];
      EXPECT_EQ(image.cols, c["width"].get<int>());
      EXPECT_EQ(image.rows, c["height"].get<int>());
      EXPECT_EQ(image.type(), CV_8UC3);
      // Not a blank image: the scene has portraits, ground and sky in view.
      cv::Scalar mean, stddev;
      cv::meanStdDev(image, mean, stddev);
      EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 10.0) << c["file"];
      EXPECT_TRUE(c.contains("joints"));
    }
  }
  // The calibration OpenCV reads back is the K the frames were rendered with.
  cv::FileStorage fs((out / "left.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  cv::Mat K;
  fs["camera_matrix"] >> K;
  const json& k = index[0]["cameras"]["left"]["K"];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(K.at<double>(r, c), k[r][c].get<double>());
  EXPECT_EQ(static_cast<int>(fs["image_width"]), index[0]["cameras"]["left"]["width"].get<int>());
  // A stereo head also gets its extrinsics: T is the baseline.
  cv::FileStorage stereo((out / "stereo.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(stereo.isOpened());
  cv::Mat T;
  stereo["T"] >> T;
  EXPECT_GT(cv::norm(T), 0.01);
}

TEST_F(RenderCli, RefusesToOverwriteWithoutForce) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(Saccade("render --scene " + kScene + " --frames 1 --out " + out.string()).status, 0);
  const auto before = fs::last_write_time(out / "left" / "000000.png");
  const CommandRun again =
      Saccade("render --scene " + kScene + " --frames 1 --out " + out.string());
  EXPECT_EQ(again.status, 1);
  EXPECT_THAT(again.output, HasSubstr("--force"));
  EXPECT_EQ(fs::last_write_time(out / "left" / "000000.png"), before);
  const CommandRun forced =
      Saccade("render --scene " + kScene + " --frames 1 --force --out " + out.string());
  EXPECT_EQ(forced.status, 0) << forced.output;
  EXPECT_EQ(Index(out).size(), 1u);
}

// Issue 46: a render killed with SIGKILL between writing a file and renaming it into place
// leaves hidden temporaries (".000003.png.tmp<pid>_<n>"); a later run with --force into the
// same folder removes them, and only them.
TEST_F(RenderCli, ForceRemovesTheTemporariesAKilledRunLeftAndNothingElse) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(Saccade("render --scene " + kScene + " --frames 1 --out " + out.string()).status, 0);
  const std::vector<fs::path> stale = {
      out / "left" / ".000001.png.tmp4194301_2", out / "right" / ".000001.png.tmp4194301_3",
      out / ".left.yaml.tmp4194301_0", out / "left" / "depth" / ".000001.png.tmp4194301_4"};
  const std::vector<fs::path> kept = {out / "left" / "notes.txt", out / "left" / ".000001.png.tmp",
                                      out / "left" / "000001.png.tmp4194301_2",
                                      out / ".left.yaml.tmpX_0", out / "README"};
  fs::create_directories(out / "left" / "depth");
  for (const auto& path : stale) std::ofstream(path) << "half a file";
  for (const auto& path : kept) std::ofstream(path) << "mine";
  const CommandRun forced =
      Saccade("render --scene " + kScene + " --frames 1 --force --out " + out.string());
  ASSERT_EQ(forced.status, 0) << forced.output;
  for (const auto& path : stale) EXPECT_FALSE(fs::exists(path)) << path;
  for (const auto& path : kept) EXPECT_TRUE(fs::exists(path)) << path;
  EXPECT_TRUE(fs::exists(out / "left" / "000000.png"));
  EXPECT_EQ(Index(out).size(), 1u);
}

TEST_F(RenderCli, InterruptedRunLeavesOnlyWholeFrames) {
  const fs::path out = dir_ / "out";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, STDOUT_FILENO);
    dup2(devnull, STDERR_FILENO);
    execl(SACCADE_BINARY, SACCADE_BINARY, "render", "--scene", kScene.c_str(), "--frames", "100000",
          "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until a few frames are out, then interrupt as Ctrl-C would.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (Index(out).size() < 3 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  kill(child, SIGINT);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const std::vector<json> index = Index(out);
  ASSERT_GE(index.size(), 3u);
  std::set<std::string> listed;
  for (const json& line : index) {
    for (const auto& [camera, entry] : line["cameras"].items()) {
      listed.insert(entry["file"].get<std::string>());
      EXPECT_FALSE(cv::imread((out / entry["file"].get<std::string>()).string()).empty());
    }
  }
  std::set<std::string> on_disk;
  for (const auto& [camera, entry] : index.front()["cameras"].items()) {
    for (const auto& file : fs::directory_iterator(out / camera)) {
      on_disk.insert(camera + "/" + file.path().filename().string());
    }
  }
  EXPECT_EQ(listed, on_disk) << "every image on disk is a listed, whole frame (no temp files)";
}

TEST_F(RenderCli, BadSceneAndJointsGiveClearErrors) {
  const fs::path bad = dir_ / "bad.yaml";
  std::ofstream(bad) << "objects:\n  - name: box\n    kind: box\n    size: [1, 1]\n";
  const CommandRun run =
      Saccade("render --scene " + bad.string() + " --out " + (dir_ / "o").string());
  EXPECT_EQ(run.status, 1);
  EXPECT_THAT(run.output, HasSubstr("bad.yaml:"));
  EXPECT_FALSE(fs::exists(dir_ / "o" / "frames.jsonl"));

  const CommandRun joints = Saccade("render --scene " + kScene + " --joints 0 80 0 0 --deg --out " +
                                    (dir_ / "j").string());
  EXPECT_EQ(joints.status, 1);
  EXPECT_THAT(joints.output, HasSubstr("tilt"));
  EXPECT_FALSE(fs::exists(dir_ / "j" / "frames.jsonl"));
}

TEST(BenchCli, ReportsFramesPerSecondAndStages) {
  const CommandRun run = Saccade("bench --scene " + std::string(SACCADE_SOURCE_DIR) +
                                 "/scenes/bench.yaml --frames 5 --warmup 1 --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const json out = json::parse(run.output);
  EXPECT_GT(out["frames_per_second"].get<double>(), 0.0);
  EXPECT_EQ(out["width"].get<int>(), 1024);
  EXPECT_EQ(out["height"].get<int>(), 768);
  EXPECT_EQ(out["cameras"].size(), 2u);
  EXPECT_GT(out["ms_per_frame"]["draw"].get<double>(), 0.0);
  EXPECT_TRUE(out["ms_per_frame"].contains("effects"));
  // Of the readback, what the CPU did of the effects: on a software rasteriser (llvmpipe here)
  // the lens remap and the noise; on a GPU nothing.
  const double cpu = out["ms_per_frame"]["cpu_effects"].get<double>();
  EXPECT_LE(cpu, out["ms_per_frame"]["readback"].get<double>());
  const std::string device = out["device"].get<std::string>();
  if (device.find("llvmpipe") != std::string::npos ||
      device.find("softpipe") != std::string::npos) {
    EXPECT_GT(cpu, 0.0) << device;
  } else {
    EXPECT_EQ(cpu, 0.0) << device;
  }
  // The default: every effect the scene describes is on.
  EXPECT_TRUE(out["distortion"].get<bool>());
  EXPECT_TRUE(out["noise"].get<bool>());
  EXPECT_TRUE(out["motion_blur"].get<bool>());
  // The cost of each effect: the bench scene configures all of them, so every run is timed.
  const json& effects = out["effects"];
  ASSERT_TRUE(effects.is_array());
  std::vector<std::string> names;
  for (const json& run : effects) {
    names.push_back(run["name"].get<std::string>());
    EXPECT_TRUE(run["configured"].get<bool>()) << run.dump();
    EXPECT_GT(run["frames_per_second"].get<double>(), 0.0) << run.dump();
    EXPECT_NEAR(run["ms_per_frame"].get<double>(), 1000.0 / run["frames_per_second"].get<double>(),
                1e-6);
    EXPECT_NEAR(run["extra_ms"].get<double>(),
                run["ms_per_frame"].get<double>() - effects[0]["ms_per_frame"].get<double>(), 1e-9);
  }
  EXPECT_THAT(names,
              ::testing::ElementsAre("off", "distortion", "noise", "motion_blur", "truth", "all"));
  EXPECT_EQ(effects[0]["extra_ms"].get<double>(), 0.0);
  EXPECT_EQ(effects[3]["head_pan_rad_per_s"].get<double>(), 2.0);  // blur needs motion
}

TEST(BenchCli, SaysWhichEffectsTheSceneDoesNotConfigure) {
  // The two-picture scene's cameras have no lens distortion, noise or exposure.
  const std::string scene = std::string(SACCADE_SOURCE_DIR) + "/scenes/astronaut_and_cat.yaml";
  const CommandRun run = Saccade("bench --scene " + scene + " --frames 2 --warmup 0");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("cost of each effect"));
  EXPECT_THAT(run.output, HasSubstr("blur is not configured"));
  EXPECT_THAT(run.output, HasSubstr("no camera of the scene has read or shot noise"));
  EXPECT_THAT(run.output, HasSubstr("truth depth+ids+boxes"));
  const CommandRun json_run =
      Saccade("bench --scene " + scene + " --frames 2 --warmup 0 --no-noise --json");
  ASSERT_EQ(json_run.status, 0) << json_run.output;
  const json out = json::parse(json_run.output);
  EXPECT_FALSE(out["noise"].get<bool>());
  for (const json& run : out["effects"]) {
    if (run["name"] == "motion_blur" || run["name"] == "noise") {
      EXPECT_FALSE(run["configured"].get<bool>()) << run.dump();
      EXPECT_TRUE(run["frames_per_second"].is_null()) << run.dump();
      EXPECT_FALSE(run["note"].get<std::string>().empty());
    }
  }
  // --no-effect-table: the first figure only.
  const CommandRun quick =
      Saccade("bench --scene " + scene + " --frames 2 --warmup 0 --no-effect-table");
  ASSERT_EQ(quick.status, 0) << quick.output;
  EXPECT_THAT(quick.output, ::testing::Not(HasSubstr("cost of each effect")));
}

}  // namespace
