// `saccade emva` used as a camera lab would: on a simulated sensor (figures as options, a scene
// camera) and on image files written here by an independent simulation (std::poisson_
// distribution, OpenCV's PNG writer), recovering the figures within issue 45's 5 %.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>

#include "e2e/run_saccade.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using saccade::e2e::CommandRun;
using saccade::e2e::Saccade;

// Issue 45: the measured figures within 5 % of the configured ones.
constexpr double kFigureTolerance = 0.05;

json ReadJson(const fs::path& path) {
  std::ifstream in(path);
  return json::parse(in);
}

void ExpectFigure(const json& result, const char* key, double configured) {
  ASSERT_TRUE(result.contains(key)) << key;
  EXPECT_NEAR(result[key].get<double>() / configured, 1.0, kFigureTolerance)
      << key << ": measured " << result[key] << ", configured " << configured;
}

fs::path Fresh(const std::string& name) {
  const fs::path dir = saccade::testing_helpers::ScratchDir() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(EmvaCli, HelpNamesTheModesAndTheFileNaming) {
  const CommandRun run = Saccade("emva --help");
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* part :
       {"EMVA 1288", "--preset", "--scene", "--images", "dark_<exposure_us>_<k>.png", "--photons",
        "--json", "--write-images", "imx174"}) {
    EXPECT_NE(run.output.find(part), std::string::npos) << part << "\n" << run.output;
  }
}

TEST(EmvaCli, MeasuresASensorGivenAsOptions) {
  const fs::path dir = Fresh("options");
  const CommandRun run = Saccade(
      "emva --gain 0.5 --dark-noise 3 --saturation 9000 --dsnu 2 --prnu 0.8 --bit-depth 14 "
      "--black-level 100 --quantum-efficiency 0.5 --size 128 --json " +
      (dir / "out.json").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("Photon transfer curve"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("<- saturation"), std::string::npos) << run.output;
  const json doc = ReadJson(dir / "out.json");
  const json& r = doc["result"];
  ExpectFigure(r, "gain_dn_per_e", 0.5);
  ExpectFigure(r, "dark_noise_e", 3.0);
  ExpectFigure(r, "saturation_e", 9000.0);
  ExpectFigure(r, "dsnu_e", 2.0);
  ExpectFigure(r, "prnu_percent", 0.8);
  ExpectFigure(r, "quantum_efficiency", 0.5);
  EXPECT_EQ(doc["source"]["sensor"]["bit_depth"], 14);
  EXPECT_GE(r["points"].size(), 40u);
}

TEST(EmvaCli, MeasuresASceneCamerasSensor) {
  const fs::path dir = Fresh("scene");
  std::ofstream(dir / "scene.yaml") << R"(cameras:
  - name: lab
    calibration: {width: 64, height: 48, fx: 50, fy: 50}
    pose: {position: [0, 0, 1]}
    sensor:
      exposure_ms: 10
      seed: 9
      emva: {preset: imx264, gain_dn_per_e: 0.3}
)";
  const CommandRun run =
      Saccade("emva --scene " + (dir / "scene.yaml").string() +
              " --camera lab --size 128 --quiet --json " + (dir / "out.json").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(run.output, "");  // --quiet
  const json doc = ReadJson(dir / "out.json");
  EXPECT_EQ(doc["source"]["camera"], "lab");
  EXPECT_EQ(doc["source"]["seed"], 9);
  ExpectFigure(doc["result"], "gain_dn_per_e", 0.3);  // the key, not the preset's 0.36
  ExpectFigure(doc["result"], "dark_noise_e", 2.3);
  ExpectFigure(doc["result"], "saturation_e", 10500.0);
}

// The simulated series written as files measures as the simulation did: the naming of
// --write-images is the naming of --images.
TEST(EmvaCli, WrittenImagesMeasureAsTheSimulatedSensor) {
  const fs::path dir = Fresh("written");
  const CommandRun simulated =
      Saccade("emva --preset imx174 --size 64 --points 20 --refine 8 --stack 4 --quiet --json " +
              (dir / "a.json").string() + " --write-images " + (dir / "frames").string());
  ASSERT_EQ(simulated.status, 0) << simulated.output;
  EXPECT_TRUE(fs::exists(dir / "frames" / "dark_0_0.png"));
  const CommandRun files = Saccade("emva --images " + (dir / "frames").string() + " --photons " +
                                   (dir / "frames" / "photons.csv").string() + " --quiet --json " +
                                   (dir / "b.json").string());
  ASSERT_EQ(files.status, 0) << files.output;
  const json a = ReadJson(dir / "a.json")["result"];
  const json b = ReadJson(dir / "b.json")["result"];
  // The same frames, one more point (the stacks' exposure): the figures agree closely.
  constexpr double kSameFramesTolerance = 0.01;
  for (const char* key : {"gain_dn_per_e", "dark_noise_e", "saturation_e", "dsnu_e", "prnu_percent",
                          "quantum_efficiency"}) {
    EXPECT_NEAR(b[key].get<double>() / a[key].get<double>(), 1.0, kSameFramesTolerance) << key;
  }
  // A second write into the same folder is refused, its files kept.
  const CommandRun again =
      Saccade("emva --preset imx174 --size 64 --write-images " + (dir / "frames").string());
  EXPECT_EQ(again.status, 1) << again.output;
  EXPECT_NE(again.output.find("expected a new or empty folder"), std::string::npos) << again.output;
}

// --- mode B: files -------------------------------------------------------------------------

// An independent camera: std::poisson_distribution electrons, Gaussian dark noise, fixed DSNU
// and PRNU patterns, a full well, 16-bit PNG through OpenCV.
struct FileCamera {
  // A large full well and a small PRNU: EMVA's saturation capacity, read where the variance
  // peaks, lies below the full well by 3 to 5 standard deviations of the signal there
  // (docs/sensor.md): here 0.6 %, so within the 5 % asked.
  double K = 0.1;             // DN / e-
  double sigma_d = 5.0;       // e-
  double saturation = 40000;  // e-
  double dsnu = 8.0;          // e-
  double prnu = 0.003;        // 0.3 %
  double offset = 50.0;       // DN
  double eta = 0.6;
  double photons_per_us = 10.0;  // a pixel's photons per microsecond of exposure
  int side = 64;
  std::mt19937_64 rng{1288};
  cv::Mat dsnu_map, prnu_map;

  FileCamera() {
    std::normal_distribution<double> normal;
    dsnu_map.create(side, side, CV_64F);
    prnu_map.create(side, side, CV_64F);
    for (int i = 0; i < side * side; ++i) {
      dsnu_map.at<double>(i) = dsnu * normal(rng);
      prnu_map.at<double>(i) = 1.0 + prnu * normal(rng);
    }
  }
  cv::Mat Frame(double exposure_us, bool dark) {
    cv::Mat out(side, side, CV_16U);
    std::normal_distribution<double> normal;
    for (int i = 0; i < side * side; ++i) {
      double e = 0.0;
      if (!dark) {
        std::poisson_distribution<int> shot(eta * photons_per_us * exposure_us *
                                            prnu_map.at<double>(i));
        e = shot(rng);
      }
      e += sigma_d * normal(rng) + dsnu_map.at<double>(i);
      e = std::min(e, saturation);
      out.at<uint16_t>(i) =
          static_cast<uint16_t>(std::clamp(std::round(K * e + offset), 0.0, 65535.0));
    }
    return out;
  }
  // The series in `dir`: pairs at `exposures`, a stack of `stack` frames at `stack_us`.
  void Write(const fs::path& dir, const std::vector<double>& exposures, double stack_us,
             int stack) {
    std::ofstream csv(dir / "photons.csv");
    csv << "exposure_us,photons\n";
    const auto write = [&](double us, int frames) {
      const std::string label = std::to_string(static_cast<int>(us));
      for (int k = 0; k < frames; ++k) {
        cv::imwrite((dir / ("dark_" + label + "_" + std::to_string(k) + ".png")).string(),
                    Frame(us, true));
        cv::imwrite((dir / ("flat_" + label + "_" + std::to_string(k) + ".png")).string(),
                    Frame(us, false));
      }
      csv << label << "," << photons_per_us * us << "\n";
    };
    for (const double us : exposures) write(us, 2);
    write(stack_us, stack);
  }
};

// Exposures (us, whole) from dark to 1.3 x saturation (40000 e- / 6 e- per us = 6667 us),
// denser around saturation.
std::vector<double> FileExposures() {
  std::vector<double> us;
  for (int k = 0; k < 30; ++k) us.push_back(std::round(k * 8667.0 / 29.0));
  for (int k = 0; k < 30; ++k) us.push_back(6100.0 + 25.0 * k);
  return us;
}

TEST(EmvaCli, MeasuresImageFilesOfAnotherSimulation) {
  const fs::path dir = Fresh("files");
  FileCamera camera;
  camera.Write(dir, FileExposures(), 3333.0, 12);
  const CommandRun run =
      Saccade("emva --images " + dir.string() + " --photons " + (dir / "photons.csv").string() +
              " --json " + (dir / "out.json").string());
  ASSERT_EQ(run.status, 0) << run.output;
  const json r = ReadJson(dir / "out.json")["result"];
  ExpectFigure(r, "gain_dn_per_e", camera.K);
  ExpectFigure(r, "dark_noise_e", camera.sigma_d);
  ExpectFigure(r, "saturation_e", camera.saturation);
  ExpectFigure(r, "dsnu_e", camera.dsnu);
  ExpectFigure(r, "prnu_percent", 100.0 * camera.prnu);
  ExpectFigure(r, "quantum_efficiency", camera.eta);
  EXPECT_EQ(r["bright_stack"]["frames"], 12);
}

TEST(EmvaCli, BadFilesAreErrorsAndLeaveNoJson) {
  const fs::path dir = Fresh("bad");
  FileCamera camera;
  camera.Write(dir, {0, 1000, 2000, 3000, 4000, 5000, 6000, 7000, 8000}, 3000.0, 2);
  const fs::path json_path = dir / "out.json";
  const auto expect_error = [&](const std::string& args, const std::string& part) {
    const CommandRun run = Saccade("emva " + args + " --json " + json_path.string());
    EXPECT_EQ(run.status, 1) << run.output;
    EXPECT_NE(run.output.find(part), std::string::npos) << part << "\n" << run.output;
    EXPECT_FALSE(fs::exists(json_path));
  };
  // A missing frame of a pair.
  fs::remove(dir / "flat_2000_1.png");
  expect_error("--images " + dir.string(), "flat_2000_1.png: missing: exposure 2000 us needs");
  cv::imwrite((dir / "flat_2000_1.png").string(), cv::Mat(32, 32, CV_16U, cv::Scalar(100)));
  expect_error("--images " + dir.string(),
               "flat_2000_1.png: a 32 x 32 frame among frames of 64 x 64");
  // Too few exposures.
  const fs::path few = Fresh("few");
  FileCamera().Write(few, {0, 1000}, 500.0, 2);
  expect_error("--images " + few.string(), "3 exposure(s) of dark_<exposure_us>_<k>.png");
  // Not a folder; a bad option.
  expect_error("--images " + (dir / "nothing").string(), "expected a folder");
  expect_error("--gain -1", "gain_dn_per_e must be a gain in DN per electron in (0, 64], got -1");
  expect_error("--images " + dir.string() + " --preset imx174", "give no --scene, --preset");
}

}  // namespace
