// The `saccade` program used as a script would: run it, parse its --json output, and check the
// numbers against the geometry they describe.

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/persistence.hpp>
#include <string>

#include "e2e/run_saccade.h"

namespace {

using nlohmann::json;
using ::testing::HasSubstr;

using saccade::e2e::CommandRun;
using saccade::e2e::Saccade;

const std::string kHead = std::string(SACCADE_SOURCE_DIR) + "/robots/popeye.yaml";

std::filesystem::path TempDir() {
  const auto dir =
      std::filesystem::temp_directory_path() / ("saccade_cli_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

Eigen::Vector3d Vec(const json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

TEST(Cli, IkThenFkFixatesTheTarget) {
  // The joints `ik` prints, fed to `fk`, must put the fixation point on the target.
  const CommandRun ik = Saccade("ik --head " + kHead + " --target 1.8 0.3 0.9 --json");
  ASSERT_EQ(ik.status, 0) << ik.output;
  const json solution = json::parse(ik.output);
  ASSERT_TRUE(solution["reachable"].get<bool>()) << ik.output;
  const json& q = solution["joints"];
  const CommandRun fk = Saccade(fmt::format(
      "fk --head {} --joints {:.17g} {:.17g} {:.17g} {:.17g} --json", kHead, q["pan"].get<double>(),
      q["tilt"].get<double>(), q["left"].get<double>(), q["right"].get<double>()));
  ASSERT_EQ(fk.status, 0) << fk.output;
  const json frames = json::parse(fk.output);
  ASSERT_FALSE(frames["fixation"].is_null());
  // Joint angles printed with 17 significant digits: the fixation moves by rounding only.
  EXPECT_LT((Vec(frames["fixation"]) - Eigen::Vector3d(1.8, 0.3, 0.9)).norm(), 1e-9);
  EXPECT_TRUE(frames["within_limits"].get<bool>());
  // Symmetric vergence by default.
  EXPECT_DOUBLE_EQ(q["left"].get<double>(), -q["right"].get<double>());
}

TEST(Cli, FkDegreesAndRadiansAgree) {
  const CommandRun deg = Saccade("fk --head " + kHead + " --joints 10 -5 -3 3 --deg --json");
  const CommandRun rad =
      Saccade(fmt::format("fk --head {} --joints {:.17g} {:.17g} {:.17g} {:.17g} --json", kHead,
                          10 * M_PI / 180, -5 * M_PI / 180, -3 * M_PI / 180, 3 * M_PI / 180));
  ASSERT_EQ(deg.status, 0) << deg.output;
  ASSERT_EQ(rad.status, 0) << rad.output;
  const json a = json::parse(deg.output), b = json::parse(rad.output);
  EXPECT_LT((Vec(a["cameras"]["left"]["position"]) - Vec(b["cameras"]["left"]["position"])).norm(),
            1e-12);
  // The right camera sits 2B from the left one whatever the joints.
  const double baseline =
      (Vec(a["cameras"]["left"]["position"]) - Vec(a["cameras"]["right"]["position"])).norm();
  EXPECT_GT(baseline, 0.0);
}

TEST(Cli, UnreachableTargetIsFlaggedAndJointsStayWithinLimits) {
  const CommandRun ik =
      Saccade("ik --head " + kHead + " --target -2 0 1.2 --json");  // behind the head
  ASSERT_EQ(ik.status, 0) << ik.output;
  const json solution = json::parse(ik.output);
  EXPECT_FALSE(solution["reachable"].get<bool>());
  EXPECT_NE(solution["reachability"].get<std::string>(), "reachable");
  EXPECT_FALSE(solution["message"].get<std::string>().empty());
  const json& q = solution["joints_deg"];
  EXPECT_LE(std::abs(q["pan"].get<double>()), 90.0 + 1e-9);
}

TEST(Cli, CameraDescribesAnOpenCvCalibrationFile) {
  const auto dir = TempDir();
  const std::string path = (dir / "camera.yml").string();
  const cv::Matx33d K(800.5, 0, 330.25, 0, 790.75, 250.5, 0, 0, 1);
  const cv::Mat D = (cv::Mat_<double>(1, 5) << -0.2, 0.05, 0.001, -0.002, 0.01);
  {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480 << "camera_matrix" << cv::Mat(K)
       << "distortion_coefficients" << D;
  }
  const CommandRun run = Saccade("camera --calibration " + path + " --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const json c = json::parse(run.output);
  EXPECT_EQ(c["width"].get<int>(), 640);
  EXPECT_EQ(c["fx"].get<double>(), 800.5);
  EXPECT_EQ(c["cy"].get<double>(), 250.5);
  EXPECT_EQ(c["distortion"]["model"].get<std::string>(), "radtan");
  EXPECT_EQ(c["distortion"]["coefficients"][0].get<double>(), -0.2);

  // The printed OpenGL matrix puts a point where cv::projectPoints (no distortion) does.
  Eigen::Matrix4d P;
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col) P(r, col) = c["gl_projection"][r][col].get<double>();
  const cv::Point3d p(0.3, -0.2, 2.5);
  std::vector<cv::Point2d> reference;
  cv::projectPoints(std::vector<cv::Point3d>{p}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                    cv::noArray(), reference);
  const Eigen::Vector4d clip = P * Eigen::Vector4d(p.x, -p.y, -p.z, 1.0);
  const double u = (clip.x() / clip.w() + 1) * 640 / 2 - 0.5;
  const double v = 480 - (clip.y() / clip.w() + 1) * 480 / 2 - 0.5;
  // JSON carries doubles with full precision (nlohmann prints 17 digits).
  EXPECT_NEAR(u, reference[0].x, 1e-9);
  EXPECT_NEAR(v, reference[0].y, 1e-9);
  std::filesystem::remove_all(dir);
}

// OpenCV's own stereo sample (stereo_calib's intrinsics.yml: M1 D1 M2 D2, no size, no R T)
// explained as the pair it is, then with an extrinsics file of R and T: the baseline, the
// angle between the optical axes and the rectification (against cv::stereoRectify's R1).
TEST(Cli, CameraExplainsAStereoCalibration) {
  const std::string intrinsics = "/usr/share/doc/opencv-doc/examples/data/intrinsics.yml";
  const CommandRun no_size = Saccade("camera --calibration " + intrinsics);
  EXPECT_EQ(no_size.status, 1) << no_size.output;
  EXPECT_THAT(no_size.output, HasSubstr("give it with --size W H"));

  const CommandRun both = Saccade("camera --calibration " + intrinsics + " --size 640 480 --json");
  ASSERT_EQ(both.status, 0) << both.output;
  const json pair = json::parse(both.output);
  EXPECT_TRUE(pair["stereo"].get<bool>());
  EXPECT_DOUBLE_EQ(pair["left"]["cx"].get<double>(), 3.3568643204394891e+02);
  EXPECT_DOUBLE_EQ(pair["right"]["cx"].get<double>(), 3.3455744527912015e+02);
  EXPECT_FALSE(pair.contains("baseline"));  // the file has no R, T
  EXPECT_THAT(Saccade("camera --calibration " + intrinsics + " --size 640 480").output,
              HasSubstr("give the pose with --extrinsics FILE"));

  const auto dir = TempDir();
  const std::string extrinsics = (dir / "extrinsics.yml").string();
  const cv::Vec3d rvec(0.01, -0.06, 0.002), T(-0.12, 0.001, 0.004);
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  {
    cv::FileStorage fs(extrinsics, cv::FileStorage::WRITE);
    fs << "R" << cv::Mat(R) << "T" << cv::Mat(T);
  }
  const CommandRun posed = Saccade("camera --calibration " + intrinsics + " --extrinsics " +
                                   extrinsics + " --size 640 480 --json");
  ASSERT_EQ(posed.status, 0) << posed.output;
  const json stereo = json::parse(posed.output);
  EXPECT_NEAR(stereo["baseline"].get<double>(), cv::norm(T), 1e-15);
  EXPECT_NEAR(stereo["rotation_deg"].get<double>(), cv::norm(rvec) * 180 / M_PI, 1e-9);
  cv::Mat R1, R2, P1, P2, Q;
  cv::stereoRectify(cv::Matx33d::eye(), cv::noArray(), cv::Matx33d::eye(), cv::noArray(),
                    cv::Size(640, 480), R, T, R1, R2, P1, P2, Q);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      // JSON carries 17 digits; the two compute the same rotations (geometry tests: 1e-12).
      EXPECT_NEAR(stereo["rectification"]["R1"][r][c].get<double>(), R1.at<double>(r, c), 1e-12);
    }
  }
  const CommandRun text = Saccade("camera --calibration " + intrinsics + " --extrinsics " +
                                  extrinsics + " --size 640 480");
  EXPECT_THAT(text.output, HasSubstr("baseline |T| 0.120070812 "));
  EXPECT_THAT(text.output, HasSubstr("rows are epipolar lines"));
  // --right is for a ROS pair, not an OpenCV file.
  const CommandRun wrong =
      Saccade("camera --calibration " + intrinsics + " --right " + intrinsics + " --size 640 480");
  EXPECT_EQ(wrong.status, 1);
  EXPECT_THAT(wrong.output, HasSubstr("--right is for a ROS pair"));
  std::filesystem::remove_all(dir);
}

TEST(Cli, BadInputsGiveClearErrors) {
  const CommandRun missing = Saccade("camera --calibration /nonexistent/calib.yml");
  EXPECT_NE(missing.status, 0);
  EXPECT_THAT(missing.output, HasSubstr("/nonexistent/calib.yml"));

  const CommandRun three_joints = Saccade("fk --head " + kHead + " --joints 1 2 3");
  EXPECT_NE(three_joints.status, 0);
  EXPECT_THAT(three_joints.output, HasSubstr("--joints"));

  const auto dir = TempDir();
  const std::string bad_head = (dir / "bad_head.yaml").string();
  {
    std::ifstream in(kHead);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string key = "\n  half_baseline:";  // the entry, not the format comment
    const auto at = text.find(key);
    ASSERT_NE(at, std::string::npos) << "robots/popeye.yaml has no half_baseline";
    text.replace(at, key.size(), key + " -0.1 #");
    std::ofstream(bad_head) << text;
  }
  const CommandRun bad = Saccade("ik --head " + bad_head + " --target 1 0 1");
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("bad_head.yaml:"));
  EXPECT_THAT(bad.output, HasSubstr("half_baseline"));
  std::filesystem::remove_all(dir);
}

TEST(Cli, LogLevelIsCheckedAndTakenBeforeOrAfterTheSubcommand) {
  const CommandRun loud = Saccade("--log-level loud fk --head " + kHead + " --joints 0 0 0 0");
  EXPECT_NE(loud.status, 0);
  EXPECT_THAT(loud.output, HasSubstr("--log-level: loud"));
  for (const std::string& args : {"--log-level off fk --head " + kHead + " --joints 0 0 0 0",
                                  "fk --head " + kHead + " --joints 0 0 0 0 --log-level debug"}) {
    const CommandRun run = Saccade(args);
    EXPECT_EQ(run.status, 0) << args << "\n" << run.output;
    EXPECT_THAT(run.output, HasSubstr("left camera")) << args;
  }
}

// Issue 18's hostile inputs, through the real program: each a clear error naming the file,
// line and key, exit status 1, never a signal (a 200000 x 200000 camera used to abort it with
// std::bad_alloc; a PLY header of 50 million faces took 3 GB and 98 s to refuse).
TEST(Cli, HugeInputsAreRefusedWithAClearErrorAndExitOne) {
  const auto dir = TempDir() / "hostile";
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name, std::ios::binary) << text;
    return (dir / name).string();
  };
  // A PNG signature and an IHDR (with its CRC) stating 100000 x 100000 pixels.
  std::string png = "\x89PNG\r\n\x1a\n";
  png += std::string("\0\0\0\x0dIHDR\0\x01\x86\xa0\0\x01\x86\xa0\x08\x02\0\0\0", 25);
  png += std::string("\x27\x30\x9c\x9f", 4);  // CRC-32 of "IHDR" and its 13 bytes
  write("huge.png", png);
  write("huge.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 50000000\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  // A binary STL of one triangle whose header says 50 million (80 header bytes, the count as
  // a little-endian uint32, 50 bytes a triangle).
  std::string stl(80, ' ');
  stl += std::string("\x80\xf0\xfa\x02", 4);  // 50000000 = 0x02faf080
  stl += std::string(50, '\0');
  write("huge.stl", stl);
  std::string pipeline = "clock: {mode: simulated, step: 0.04, steps: 1}\ncomponents:\n";
  for (int i = 0; i < 10000; ++i) {
    pipeline += "  - {name: c" + std::to_string(i) + ", type: vision.stereo_faces}\n";
  }
  struct Case {
    std::string command, expected;
  };
  const std::vector<Case> cases = {
      {"render --frames 1 --force --out " + (dir / "out").string() + " --scene " +
           write("camera.yaml",
                 "cameras:\n  - name: huge\n    calibration: {width: 200000, height: 200000, "
                 "fx: 1e5, fy: 1e5}\n    look_at: {eye: [0, 0, 1], target: [1, 0, 1]}\n"),
       "camera.yaml:3: cameras[0].calibration: camera 'huge' is 200000x200000 px"},
      {"render --frames 1 --force --out " + (dir / "out").string() + " --scene " +
           write("picture.yaml",
                 "objects:\n  - {name: poster, kind: picture, image: huge.png, height: 1}\n"),
       "huge.png: the image is 100000x100000 px, larger than saccade reads"},
      {"render --frames 1 --force --out " + (dir / "out").string() + " --scene " +
           write("model.yaml", "objects:\n  - {name: blob, kind: model, file: huge.ply}\n"),
       "huge.ply: the PLY header declares 50000000 faces"},
      {"render --frames 1 --force --out " + (dir / "out").string() + " --scene " +
           write("stl.yaml", "objects:\n  - {name: blob, kind: model, file: huge.stl}\n"),
       "huge.stl: the binary STL header declares 50000000 triangles"},
      // A device never ends: configuration files are read only when regular, and bounded.
      {"fk --head /dev/zero --joints 0 0 0 0",
       "/dev/zero: not a regular file (a folder, device or pipe); expected a head file"},
      {"camera --calibration /dev/zero",
       "/dev/zero: not a regular file (a device or pipe), expected a calibration file"},
      {"demo --pipeline /dev/zero",
       "/dev/zero: not a regular file (a folder, device or pipe); expected a pipeline file"},
      {"demo --hardware /dev/zero",
       "/dev/zero: not a regular file (a folder, device or pipe); expected a hardware file"},
      {"demo --pipeline " + write("pipeline.yaml", pipeline),
       "pipeline.yaml:3: components: 10000 components, more than the 1000"},
  };
  for (const Case& c : cases) {
    const CommandRun run = Saccade(c.command);
    EXPECT_EQ(run.status, 1) << c.command << "\n" << run.output;  // 1, not a signal's 128+
    EXPECT_THAT(run.output, HasSubstr(c.expected)) << c.command;
  }
  std::filesystem::remove_all(dir.parent_path());
}

TEST(Cli, EverySubcommandHasHelp) {
  for (const char* sub : {"fk", "ik", "camera", "demo", "run"}) {
    const CommandRun help = Saccade(std::string(sub) + " --help");
    EXPECT_EQ(help.status, 0) << sub;
    EXPECT_THAT(help.output, HasSubstr("Usage")) << sub;
  }
}

}  // namespace
