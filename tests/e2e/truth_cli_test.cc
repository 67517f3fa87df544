// `saccade render --truth` and the effect switches, used as a person would: a scene with a box
// at a known distance, the files read back by OpenCV and checked against the geometry.

#include <fcntl.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "e2e/run_saccade.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

using saccade::e2e::CommandRun;
using saccade::e2e::Saccade;

// A 320 x 240 pinhole camera 1 m above the (hidden) ground looking along world +x, and a box
// (id 7) whose front face, 0.6 x 0.6 m, is square to the optical axis at z = 2 m: every pixel of
// that face has depth 2 m. Nothing else is in view: the rest is sky (depth 0, id 0).
constexpr double kFaceZ = 2.0;       // metres: the front face's depth
constexpr double kBoxCentreZ = 2.1;  // metres: the box is 0.2 m deep
constexpr double kHalfFace = 0.3;    // metres
constexpr double kF = 300.0;         // pixels
constexpr double kCx = 159.5, kCy = 119.5;
constexpr int kWidth = 320, kHeight = 240;
constexpr uint32_t kBoxId = 7;
// Depth is written in whole millimetres, rounded to nearest.
constexpr double kDepthToleranceMm = 1.0;
// The box edge from the id image: a pixel is the box's when its centre sees the box, so the
// edges land within a pixel of the projected ones (plus rasterisation's half pixel).
constexpr double kBoxTolerancePx = 1.5;
// X_CO comes from double-precision poses through the renderer: exact but for rounding.
constexpr double kPoseTolerance = 1e-9;

const std::string kSceneText = R"(ground: {enabled: false}
objects:
  - name: crate
    kind: box
    id: 7
    size: [0.2, 0.6, 0.6]
    color: [0.8, 0.3, 0.2]
    pose: {position: [2.1, 0, 1]}
cameras:
  - name: cam
    calibration: {width: 320, height: 240, fx: 300, fy: 300, cx: 159.5, cy: 119.5}
    look_at: {eye: [0, 0, 1], target: [2, 0, 1]}
)";

// The same camera with a lens: radtan, barrel.
const std::string kDistortion = "distortion: {model: radtan, coefficients: [-0.2, 0.05, 0, 0]}";

class TruthCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("saccade_truth_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path WriteScene(const std::string& text, const std::string& name = "scene.yaml") const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  std::vector<json> Index(const fs::path& out) const {
    std::vector<json> lines;
    std::ifstream in(out / "frames.jsonl");
    for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
    return lines;
  }
  // The distortion coefficients of an OpenCV calibration file, as doubles.
  static std::vector<double> FileDistortion(const fs::path& path, const char* key) {
    cv::FileStorage fs(path.string(), cv::FileStorage::READ);
    EXPECT_TRUE(fs.isOpened()) << path;
    cv::Mat D;
    fs[key] >> D;
    std::vector<double> out;
    for (int i = 0; i < static_cast<int>(D.total()); ++i) out.push_back(D.at<double>(i));
    return out;
  }

  fs::path dir_;
};

TEST_F(TruthCli, DepthIdsAndBoxesMatchTheScenesGeometry) {
  const fs::path out = dir_ / "out";
  const CommandRun run = Saccade("render --scene " + WriteScene(kSceneText).string() +
                                 " --frames 2 --truth depth,ids,boxes --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const std::vector<json> index = Index(out);
  ASSERT_EQ(index.size(), 2u);
  for (int frame = 0; frame < 2; ++frame) {
    const json& cam = index[frame]["cameras"]["cam"];
    ASSERT_EQ(cam["depth"].get<std::string>(), fmt::format("cam/depth/{:06d}.png", frame));
    ASSERT_EQ(cam["ids"].get<std::string>(), fmt::format("cam/ids/{:06d}.png", frame));

    const cv::Mat depth =
        cv::imread((out / cam["depth"].get<std::string>()).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat ids =
        cv::imread((out / cam["ids"].get<std::string>()).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(depth.empty());
    ASSERT_FALSE(ids.empty());
    EXPECT_EQ(depth.type(), CV_16UC1);
    EXPECT_EQ(ids.type(), CV_16UC1);
    EXPECT_EQ(depth.cols, kWidth);
    EXPECT_EQ(depth.rows, kHeight);
    EXPECT_EQ(ids.cols, kWidth);
    EXPECT_EQ(ids.rows, kHeight);

    // The centre sees the box's front face at 2 m; the corners see sky.
    const int u = static_cast<int>(std::round(kCx)), v = static_cast<int>(std::round(kCy));
    EXPECT_NEAR(depth.at<uint16_t>(v, u), kFaceZ * 1000.0, kDepthToleranceMm);
    EXPECT_EQ(ids.at<uint16_t>(v, u), kBoxId);
    const std::array<std::pair<int, int>, 3> corners = {
        {{0, 0}, {kWidth - 1, 0}, {0, kHeight - 1}}};
    for (const auto& [x, y] : corners) {
      EXPECT_EQ(depth.at<uint16_t>(y, x), 0) << x << ", " << y;
      EXPECT_EQ(ids.at<uint16_t>(y, x), 0) << x << ", " << y;
    }
    // Every box pixel has the face's depth; every other pixel none.
    int box_pixels = 0;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const uint16_t id = ids.at<uint16_t>(y, x);
        ASSERT_TRUE(id == 0 || id == kBoxId) << id;
        if (id == kBoxId) {
          ++box_pixels;
          ASSERT_NEAR(depth.at<uint16_t>(y, x), kFaceZ * 1000.0, kDepthToleranceMm)
              << x << ", " << y;
        } else {
          ASSERT_EQ(depth.at<uint16_t>(y, x), 0) << x << ", " << y;
        }
      }
    }

    // The box in frames.jsonl: the projected face, its pixel count and its pose.
    ASSERT_TRUE(cam["objects"].is_array()) << cam.dump();
    ASSERT_EQ(cam["objects"].size(), 1u) << cam["objects"].dump();
    const json& crate = cam["objects"][0];
    EXPECT_EQ(crate["id"].get<uint32_t>(), kBoxId);
    EXPECT_EQ(crate["name"].get<std::string>(), "crate");
    EXPECT_EQ(crate["pixels"].get<int>(), box_pixels);
    const std::vector<int> box = crate["box"].get<std::vector<int>>();
    ASSERT_EQ(box.size(), 4u);
    EXPECT_LE(box[0], kCx);
    EXPECT_LE(box[1], kCy);
    EXPECT_GE(box[2], kCx);
    EXPECT_GE(box[3], kCy);
    const double half = kF * kHalfFace / kFaceZ;  // 45 px
    EXPECT_NEAR(box[0], kCx - half, kBoxTolerancePx);
    EXPECT_NEAR(box[1], kCy - half, kBoxTolerancePx);
    EXPECT_NEAR(box[2], kCx + half, kBoxTolerancePx);
    EXPECT_NEAR(box[3], kCy + half, kBoxTolerancePx);
    // X_CO: the box's centre straight ahead, 2.1 m; its x axis (world x) is the optical axis.
    const json& X_CO = crate["X_CO"];
    ASSERT_EQ(X_CO.size(), 4u);
    const double expected[4][4] = {
        {0, -1, 0, 0}, {0, 0, -1, 0}, {1, 0, 0, kBoxCentreZ}, {0, 0, 0, 1}};
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        EXPECT_NEAR(X_CO[r][c].get<double>(), expected[r][c], kPoseTolerance) << r << ", " << c;
      }
    }
  }
}

TEST_F(TruthCli, AnySubsetWritesOnlyWhatWasAskedFor) {
  const fs::path out = dir_ / "out";
  const CommandRun run = Saccade("render --scene " + WriteScene(kSceneText).string() +
                                 " --truth boxes --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const json cam = Index(out).at(0)["cameras"]["cam"];
  EXPECT_FALSE(cam.contains("depth"));
  EXPECT_FALSE(cam.contains("ids"));
  EXPECT_EQ(cam["objects"].size(), 1u);
  EXPECT_FALSE(fs::exists(out / "cam" / "depth"));
  EXPECT_FALSE(fs::exists(out / "cam" / "ids"));
  // No --truth: none of it.
  const CommandRun plain = Saccade("render --scene " + (dir_ / "scene.yaml").string() +
                                   " --force --out " + out.string());
  ASSERT_EQ(plain.status, 0) << plain.output;
  const json c = Index(out).at(0)["cameras"]["cam"];
  EXPECT_FALSE(c.contains("depth") || c.contains("ids") || c.contains("objects")) << c.dump();
}

TEST_F(TruthCli, BadTruthItemsNameTheItemAndTheValidOnes) {
  const fs::path scene = WriteScene(kSceneText);
  const CommandRun run = Saccade("render --scene " + scene.string() +
                                 " --truth depth,normals --out " + (dir_ / "o").string());
  EXPECT_EQ(run.status, 1);
  EXPECT_THAT(run.output, HasSubstr("saccade: error: render: --truth: unknown item 'normals'"));
  EXPECT_THAT(run.output, HasSubstr("depth, ids, boxes"));
  EXPECT_FALSE(fs::exists(dir_ / "o" / "frames.jsonl"));

  const CommandRun empty = Saccade("render --scene " + scene.string() +
                                   " --truth depth,,ids --out " + (dir_ / "o").string());
  EXPECT_EQ(empty.status, 1);
  EXPECT_THAT(empty.output, HasSubstr("--truth 'depth,,ids': an empty item"));
  EXPECT_FALSE(fs::exists(dir_ / "o" / "frames.jsonl"));

  const CommandRun nothing =
      Saccade("render --scene " + scene.string() + " --truth '' --out " + (dir_ / "o").string());
  EXPECT_EQ(nothing.status, 1);
  EXPECT_THAT(nothing.output, HasSubstr("--truth '': an empty item"));
}

TEST_F(TruthCli, IdsAbove65535AreRefusedForTheIdImagesNamingTheObject) {
  std::string text = kSceneText;
  text.replace(text.find("id: 7"), 5, "id: 70000");
  const fs::path scene = WriteScene(text);
  const CommandRun run = Saccade("render --scene " + scene.string() + " --truth depth,ids --out " +
                                 (dir_ / "o").string());
  EXPECT_EQ(run.status, 1);
  EXPECT_THAT(run.output, HasSubstr("object 'crate' has instance id 70000"));
  EXPECT_THAT(run.output, HasSubstr("16-bit"));
  EXPECT_THAT(run.output, HasSubstr("65535"));
  EXPECT_FALSE(fs::exists(dir_ / "o" / "frames.jsonl"));
}

TEST_F(TruthCli, BoxesAndDepthWorkWithLargeIds) {
  // Without id images, a large id is fine: it only appears in frames.jsonl.
  std::string text = kSceneText;
  text.replace(text.find("id: 7"), 5, "id: 70000");
  const fs::path out = dir_ / "out";
  const CommandRun run = Saccade("render --scene " + WriteScene(text).string() +
                                 " --truth depth,boxes --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const json cam = Index(out).at(0)["cameras"]["cam"];
  ASSERT_EQ(cam["objects"].size(), 1u);
  EXPECT_EQ(cam["objects"][0]["id"].get<uint32_t>(), 70000u);
}

TEST_F(TruthCli, CalibrationFilesCarryTheRenderedDistortion) {
  std::string text = kSceneText;
  text.replace(text.find("cy: 119.5}"), 10, "cy: 119.5, " + kDistortion + "}");
  const fs::path scene = WriteScene(text);

  // Distortion rendered (the default): the files carry the lens's coefficients, as the frames'
  // metadata says (OpenCV's order k1 k2 p1 p2 k3 k4 k5 k6, trailing zeros included or not).
  const fs::path out = dir_ / "lens";
  const CommandRun run = Saccade("render --scene " + scene.string() + " --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, ::testing::Not(HasSubstr("warning")));
  const json meta = Index(out).at(0)["cameras"]["cam"]["distortion"];
  EXPECT_EQ(meta["model"].get<std::string>(), "radtan");
  const std::vector<double> lens = {-0.2, 0.05, 0.0, 0.0};
  const std::vector<double> file = FileDistortion(out / "cam.yaml", "distortion_coefficients");
  ASSERT_GE(file.size(), lens.size());
  for (std::size_t k = 0; k < file.size(); ++k) {
    EXPECT_DOUBLE_EQ(file[k], k < lens.size() ? lens[k] : 0.0) << k;
  }

  // --no-distortion: the pinhole of K; files and metadata say no distortion.
  const fs::path pinhole = dir_ / "pinhole";
  const CommandRun off =
      Saccade("render --scene " + scene.string() + " --no-distortion --out " + pinhole.string());
  ASSERT_EQ(off.status, 0) << off.output;
  EXPECT_EQ(Index(pinhole).at(0)["cameras"]["cam"]["distortion"]["model"].get<std::string>(),
            "none");
  for (double k : FileDistortion(pinhole / "cam.yaml", "distortion_coefficients")) {
    EXPECT_EQ(k, 0.0);
  }
}

TEST_F(TruthCli, NoDistortionGivesAStereoFileWithZeroDistortion) {
  // The bench scene's eye cameras have radtan lenses.
  const fs::path out = dir_ / "out";
  const CommandRun run =
      Saccade("render --scene " + std::string(SACCADE_SOURCE_DIR) +
              "/scenes/bench.yaml --no-distortion --no-noise --no-blur --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* key : {"D1", "D2"}) {
    for (double k : FileDistortion(out / "stereo.yaml", key)) EXPECT_EQ(k, 0.0) << key;
  }
  for (const char* camera : {"left.yaml", "right.yaml"}) {
    for (double k : FileDistortion(out / camera, "distortion_coefficients")) {
      EXPECT_EQ(k, 0.0) << camera;
    }
  }
}

TEST_F(TruthCli, StereoFileCarriesTheEyesRenderedDistortion) {
  const fs::path out = dir_ / "out";
  const CommandRun run = Saccade("render --scene " + std::string(SACCADE_SOURCE_DIR) +
                                 "/scenes/bench.yaml --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const json left = Index(out).at(0)["cameras"]["left"]["distortion"];
  EXPECT_EQ(left["model"].get<std::string>(), "radtan");
  const std::vector<double> D1 = FileDistortion(out / "stereo.yaml", "D1");
  const std::vector<double> meta = left["coefficients"].get<std::vector<double>>();
  ASSERT_FALSE(D1.empty());
  for (std::size_t k = 0; k < D1.size(); ++k) {
    EXPECT_DOUBLE_EQ(D1[k], k < meta.size() ? meta[k] : 0.0) << k;
  }
  EXPECT_DOUBLE_EQ(D1[0], -0.2);  // k1 of scenes/bench.yaml's left eye
}

TEST_F(TruthCli, InterruptedRunLeavesOnlyWholeFramesTruthIncluded) {
  const fs::path out = dir_ / "out";
  const std::string scene = WriteScene(kSceneText).string();
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, STDOUT_FILENO);
    dup2(devnull, STDERR_FILENO);
    execl(SACCADE_BINARY, SACCADE_BINARY, "render", "--scene", scene.c_str(), "--frames", "100000",
          "--truth", "depth,ids,boxes", "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Wait until a few frames are out, then interrupt as Ctrl-C would.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (Index(out).size() < 3 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
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
    const json& cam = line["cameras"]["cam"];
    for (const char* key : {"file", "depth", "ids"}) {
      const std::string file = cam[key].get<std::string>();
      listed.insert(file);
      EXPECT_FALSE(cv::imread((out / file).string(), cv::IMREAD_UNCHANGED).empty()) << file;
    }
  }
  std::set<std::string> on_disk;
  for (const auto& entry : fs::recursive_directory_iterator(out / "cam")) {
    if (entry.is_regular_file()) on_disk.insert(fs::relative(entry.path(), out).string());
  }
  EXPECT_EQ(listed, on_disk) << "every image on disk is a listed, whole frame (no temp files)";
}

TEST_F(TruthCli, HelpDocumentsTheTruthFilesAndTheEffectSwitches) {
  const CommandRun render = Saccade("render --help");
  EXPECT_EQ(render.status, 0);
  for (const char* text : {"--truth", "depth, ids, boxes", "millimetres", "65.535 m", "16-bit",
                           "--no-distortion", "--no-noise", "--no-blur"}) {
    EXPECT_THAT(render.output, HasSubstr(text));
  }
  const CommandRun bench = Saccade("bench --help");
  EXPECT_EQ(bench.status, 0);
  for (const char* text : {"--no-distortion", "--no-noise", "--no-blur", "--no-effect-table"}) {
    EXPECT_THAT(bench.output, HasSubstr(text));
  }
}

}  // namespace
