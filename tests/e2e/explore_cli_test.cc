// `saccade explore` as a user runs it: a short exploration of the wall of pictures with one
// strategy, its JSON report and its map; and bad settings refused with file, line and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "run_saccade.h"
#include "scratch_dir.h"

namespace saccade::e2e {
namespace {

TEST(ExploreCli, ReportsAndMapsAShortExploration) {
  const std::filesystem::path dir = testing_helpers::FreshScratchDir("explore");
  const std::filesystem::path settings = dir / "fast.yaml";
  std::ofstream(settings)
      << "raster_step: 1.5\nmap: {stride: 4}\nstereo: {scale: 0.5}\n"
         "score: {truth_cell_m: 0.02, truth_step: 1.0}\n";
  const CommandRun run = Saccade(
      "explore --scene scenes/explore_wall.yaml --strategy saliency "
      "--seconds 1.5 --quiet --config " +
      settings.string() + " --json - --map-dir " + dir.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output);
  EXPECT_EQ(report["head"], "popeye");
  ASSERT_EQ(report["strategies"].size(), 1u);
  const nlohmann::json& s = report["strategies"][0];
  EXPECT_EQ(s["strategy"], "saliency");
  EXPECT_GE(s["fixations"].get<int>(), 2);
  EXPECT_GT(s["map"]["completeness"].get<double>(), 0.0);
  EXPECT_LE(s["map"]["completeness"].get<double>(), 1.0);
  EXPECT_EQ(s["saccade_amplitudes_deg"].size(), s["fixations"].get<std::size_t>());
  EXPECT_FALSE(s["completeness_curve"].empty());
  // The map, a PLY with as many points as the report's voxels.
  std::ifstream ply(dir / "saliency.ply", std::ios::binary);
  std::string line;
  std::getline(ply, line);
  EXPECT_EQ(line, "ply");
  bool counted = false;
  while (std::getline(ply, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) {
      EXPECT_EQ(std::stoll(line.substr(15)), s["map_voxels"].get<int64_t>());
      counted = true;
    }
  }
  EXPECT_TRUE(counted);
}

TEST(ExploreCli, RefusesBadSettingsWithFileLineAndKey) {
  const std::filesystem::path dir = testing_helpers::FreshScratchDir("explore_bad");
  const std::filesystem::path settings = dir / "bad.yaml";
  std::ofstream(settings) << "seconds: 10\nior:\n  time_constant_s: -1\n";
  CommandRun run =
      Saccade("explore --scene scenes/explore_wall.yaml --config " + settings.string());
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.output.find("bad.yaml:3: ior.time_constant_s"), std::string::npos) << run.output;
  run = Saccade("explore --strategy spiral");
  EXPECT_NE(run.status, 0);
  EXPECT_NE(run.output.find("spiral"), std::string::npos) << run.output;
  run = Saccade("explore --scene scenes/explore_wall.yaml --seconds -1");
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.output.find("seconds"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace saccade::e2e
