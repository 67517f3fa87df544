// Exploration (issue 44): deterministic in simulated time, every strategy maps what it looks
// at, and bad settings are refused naming the file, the line and the key.
#include "saccade/components/explore_session.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iostream>

#include "saccade/core/error.h"
#include "scratch_dir.h"

namespace saccade::components {
namespace {

const scene::Scene& Wall() {
  static const scene::Scene scene =
      scene::Scene::Load(std::string(SACCADE_SOURCE_DIR) + "/scenes/explore_wall.yaml");
  return scene;
}

// Short runs: a coarse raster (and truth), two simulated seconds, stereo at half size (a quarter
// of full size's cost). A coarse raster's views hardly overlap, so one hit makes a voxel
// occupied here (the default takes two fixations' hits).
ExploreOptions Short(const std::string& strategy) {
  ExploreOptions options;
  options.strategy = strategy;
  options.seconds = 2.0;
  options.raster_step = 1.5;
  options.truth_step = 1.0;
  options.truth_cell_m = 0.02;
  options.map.stride = 4;
  options.map.occupancy_threshold = 0.5;
  options.stereo.scale = 0.5;
  return options;
}

const ExploreTruth& Truth() {
  static const ExploreTruth truth = MakeExploreTruth(Wall(), Short("raster"));
  return truth;
}

TEST(Explore, IsDeterministicInSimulatedTime) {
  for (const std::string& strategy : ExploreStrategies()) {
    mapping::WorldMap map_a(mapping::WorldMap::Options{}), map_b(mapping::WorldMap::Options{});
    const ExploreReport a = Explore(Wall(), Short(strategy), Truth(), &map_a);
    const ExploreReport b = Explore(Wall(), Short(strategy), Truth(), &map_b);
    std::cout << strategy << ": " << a.fixations << " fixations, completeness "
              << a.score.completeness << ", rms " << a.score.rms_m * 1000 << " mm\n";
    ASSERT_GE(a.fixations, 3) << strategy;
    EXPECT_EQ(a.fixations, b.fixations) << strategy;
    EXPECT_EQ(a.fixation_points_W, b.fixation_points_W) << strategy;
    EXPECT_EQ(a.saccade_amplitudes_deg, b.saccade_amplitudes_deg) << strategy;
    ASSERT_EQ(a.curve.size(), b.curve.size()) << strategy;
    for (std::size_t i = 0; i < a.curve.size(); ++i) {
      EXPECT_EQ(a.curve[i].completeness, b.curve[i].completeness) << strategy << " sample " << i;
    }
    EXPECT_EQ(map_a.OccupiedCentres(), map_b.OccupiedCentres()) << strategy;
    // What it looked at is mapped, and mapped where the surfaces are.
    EXPECT_GT(a.score.completeness, 0.05) << strategy;
    EXPECT_LT(a.score_1_to_3m.rms_m, 0.03) << strategy;
    // Completeness never falls by more than stray voxels cleared.
    for (std::size_t i = 1; i < a.curve.size(); ++i) {
      EXPECT_GE(a.curve[i].completeness, a.curve[i - 1].completeness - 0.01) << strategy;
    }
  }
}

// A different seed makes other random saccades; raster does not depend on it.
TEST(Explore, TheSeedChangesRandomSaccadesOnly) {
  ExploreOptions random = Short("random"), raster = Short("raster");
  const ExploreReport a = Explore(Wall(), random, Truth());
  random.seed = 2;
  const ExploreReport b = Explore(Wall(), random, Truth());
  EXPECT_NE(a.fixation_points_W, b.fixation_points_W);
  const ExploreReport c = Explore(Wall(), raster, Truth());
  raster.seed = 2;
  const ExploreReport d = Explore(Wall(), raster, Truth());
  EXPECT_EQ(c.fixation_points_W, d.fixation_points_W);
}

// The saliency strategy's novelty, on a constructed map (a wall 1 x 1 m at x = 2 m): high toward
// unknown space, less where fixations looked and stereo mapped nothing, the tentative value toward
// a surface seen once, none toward the mapped surface or free space to the range.
TEST(RayNovelty, IsHighTowardUnknownSpaceAndLowTowardTheMap) {
  std::vector<Eigen::Vector3d> wall;
  for (double y = -0.5; y <= 0.5; y += 0.005) {
    for (double z = -0.5; z <= 0.5; z += 0.005) wall.emplace_back(2.0, y, z);
  }
  mapping::WorldMap map(mapping::WorldMap::Options{});
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  const Eigen::Vector3d to_wall(1, 0, 0), aside(0, 1, 0);
  EXPECT_EQ(RayNovelty(map, origin, to_wall, 5.0, 0, 0.7), 1.0);  // nothing mapped yet
  map.FusePoints(wall, origin);
  EXPECT_EQ(RayNovelty(map, origin, aside, 5.0, 0, 0.7), 1.0);
  EXPECT_EQ(RayNovelty(map, origin, aside, 5.0, 2, 0.7), 0.25);     // looked at twice, nothing
  EXPECT_EQ(RayNovelty(map, origin, to_wall, 5.0, 1, 0.7), 0.7);    // seen once
  EXPECT_EQ(RayNovelty(map, origin, to_wall, 5.0, 4, 0.7), 0.175);  // looked 4 times, still once
  EXPECT_EQ(RayNovelty(map, origin, to_wall, 1.5, 1, 0.7), 0.0);    // free to the range
  map.FusePoints(wall, origin);
  EXPECT_EQ(RayNovelty(map, origin, to_wall, 5.0, 2, 0.7), 0.0);  // mapped
}

std::string ErrorOf(const std::string& yaml) {
  const std::filesystem::path file = testing_helpers::ScratchFile("explore.yaml");
  std::ofstream(file) << yaml;
  try {
    LoadExploreConfig(file);
  } catch (const FileError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ExploreConfig, RefusesBadSettingsNamingFileLineAndKey) {
  EXPECT_NE(
      ErrorOf("seconds: 5\nmap:\n  resolution_m: 0\n").find("explore.yaml:3: map.resolution_m"),
      std::string::npos)
      << ErrorOf("seconds: 5\nmap:\n  resolution_m: 0\n");
  EXPECT_NE(ErrorOf("ior: {time_constant_s: -1}\n").find("explore.yaml:1: ior.time_constant_s"),
            std::string::npos)
      << ErrorOf("ior: {time_constant_s: -1}\n");
  const std::string spiral = ErrorOf("strategies:\n  - raster\n  - spiral\n");
  EXPECT_NE(spiral.find("explore.yaml:3"), std::string::npos) << spiral;
  EXPECT_NE(spiral.find("'spiral' is not a strategy"), std::string::npos) << spiral;
  EXPECT_NE(ErrorOf("map: {voxel: 0.1}\n").find("voxel"), std::string::npos);
  EXPECT_NE(ErrorOf("stereo: {block_size: 4}\n").find("stereo.block_size"), std::string::npos);
  EXPECT_NE(ErrorOf("attention: {tentative_value: -1}\n")
                .find("explore.yaml:1: attention.tentative_value"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf("attention: {candidate_step: 0}\n").find("explore.yaml:1: attention.candidate_step"),
      std::string::npos);
  EXPECT_EQ(ErrorOf("seconds: 5\nmap: {resolution_m: 0.05}\n"), "(accepted)");
  // The shipped settings are the defaults.
  const ExploreConfig shipped =
      LoadExploreConfig(std::string(SACCADE_SOURCE_DIR) + "/config/explore.yaml");
  const ExploreOptions defaults;
  EXPECT_EQ(shipped.strategies, ExploreStrategies());
  EXPECT_EQ(shipped.options.seconds, defaults.seconds);
  EXPECT_EQ(shipped.options.map.resolution_m, defaults.map.resolution_m);
  EXPECT_EQ(shipped.options.ior_time_constant_s, defaults.ior_time_constant_s);
  EXPECT_EQ(shipped.options.stereo.min_depth_m, defaults.stereo.min_depth_m);
  EXPECT_EQ(shipped.options.stereo.scale, defaults.stereo.scale);
  EXPECT_EQ(shipped.options.candidate_step, defaults.candidate_step);
  EXPECT_EQ(shipped.options.tentative_value, defaults.tentative_value);
}

TEST(ExploreOptions, RefusesAStrategyThatDoesNotExist) {
  ExploreOptions options;
  options.strategy = "spiral";
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("strategy: 'spiral' does not exist"), std::string::npos) << error;
  EXPECT_THROW(Explore(Wall(), options, Truth()), InvalidArgument);
}

}  // namespace
}  // namespace saccade::components
