// `saccade urdf`: a head file's URDF, for ROS tools (issue 42, item 5).

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "e2e/run_saccade.h"
#include "saccade/head/urdf.h"

namespace {

namespace fs = std::filesystem;
using saccade::e2e::CommandRun;
using saccade::e2e::Saccade;
using ::testing::HasSubstr;

const fs::path kSource = SACCADE_SOURCE_DIR;

fs::path TempDir() {
  const fs::path dir = fs::temp_directory_path() / fmt::format("saccade_urdf_cli_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), {}};
}

TEST(UrdfCli, PopeyesUrdfParsesWithUrdfdomWithFourRevoluteJoints) {
  const fs::path dir = TempDir();
  const fs::path out = dir / "popeye.urdf";
  const CommandRun run = Saccade(
      fmt::format("urdf --head {} -o {}", (kSource / "robots/popeye.yaml").string(), out.string()));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(run.output, "");  // no warnings: POPEYE's cameras are Gazebo's
  const std::string xml = ReadFile(out);
  const saccade::head::UrdfModel urdf = saccade::head::ParseUrdf(xml, out.string(), dir);
  int revolute = 0;
  for (int j = 0; j < urdf.tree.num_joints(); ++j) {
    revolute += urdf.tree.joint(j).type == saccade::head::JointType::kRevolute;
  }
  EXPECT_EQ(revolute, 4);
  EXPECT_EQ(urdf.cameras.size(), 2u);
  // Nothing but the URDF in the folder: the temporary was renamed.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  // Without -o the same text goes to standard output.
  const CommandRun stdout_run =
      Saccade(fmt::format("urdf --head {}", (kSource / "robots/popeye.yaml").string()));
  ASSERT_EQ(stdout_run.status, 0) << stdout_run.output;
  EXPECT_EQ(stdout_run.output, xml);
  fs::remove_all(dir);
}

TEST(UrdfCli, AHeadWithAUrdfGetsThatFileUnchanged) {
  const CommandRun run =
      Saccade(fmt::format("urdf --head {}", (kSource / "robots/humanoid.yaml").string()));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(run.output, ReadFile(kSource / "robots/humanoid/humanoid.urdf"));
}

TEST(UrdfCli, AMissingHeadFileIsAnErrorNamingItAndWritesNothing) {
  const fs::path dir = TempDir();
  const fs::path out = dir / "out.urdf";
  const std::string missing = (dir / "no_such_head.yaml").string();
  const CommandRun run = Saccade(fmt::format("urdf --head {} -o {}", missing, out.string()));
  EXPECT_NE(run.status, 0);
  EXPECT_THAT(run.output, HasSubstr("saccade: error: " + missing));
  EXPECT_THAT(run.output, HasSubstr("does not exist"));
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST(UrdfCli, ACameraGazeboCannotExpressGivesWarningsOnStderr) {
  const fs::path dir = TempDir();
  const fs::path out = dir / "calibrated.urdf";
  const CommandRun run =
      Saccade(fmt::format("urdf --head {} -o {}",
                          (kSource / "fuzz/corpus/head/calibrated.yaml").string(), out.string()));
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("saccade: warning: "));
  EXPECT_THAT(run.output, HasSubstr("fx 520.5 != fy 519.8"));
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
