// Exit statuses, the same for every subcommand (docs/cli.md, "Exit statuses"): bad input of any
// kind (an unknown subcommand or option, a value out of range, a missing or wrong file) gives
// status 1 and a message on stderr that names what was wrong; --help and --version give 0.
// CLI11 alone would exit 104-114 on usage errors, and 0 for `saccade wander --help`.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "e2e/run_saccade.h"

namespace {

using saccade::e2e::CommandRun;
using saccade::e2e::Saccade;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kSource = SACCADE_SOURCE_DIR;
const std::string kHead = kSource + "/robots/popeye.yaml";

struct Case {
  std::string args;      // after `saccade`
  std::string expected;  // in the message
};

// Each case fails on its input before any real work (no window, no port, no frames).
void ExpectStatusOne(const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    const CommandRun run = Saccade(c.args);
    EXPECT_EQ(run.status, 1) << "saccade " << c.args << "\n" << run.output;
    EXPECT_THAT(run.output, HasSubstr("saccade: error: ")) << "saccade " << c.args;
    EXPECT_THAT(run.output, HasSubstr(c.expected)) << "saccade " << c.args;
  }
}

TEST(ExitStatus, UsageErrorsOfEverySubcommandExitOne) {
  std::vector<Case> cases;
  for (const std::string sub :
       {"fk", "ik", "camera", "render", "bench", "demo", "gui", "run", "urdf", "explore", "emva"}) {
    cases.push_back({sub + " --no-such-option", "--no-such-option"});
  }
  // Values out of range or of the wrong type, one per subcommand (CLI11's checks).
  cases.push_back({"fk --head " + kHead + " --joints 1 2 3", "--joints"});
  cases.push_back({"ik --head " + kHead + " --target 1 x 1", "--target"});
  cases.push_back({"camera", "--calibration"});  // required
  cases.push_back({"render --scene " + kSource + "/scenes/portraits.yaml --frames 0", "--frames"});
  cases.push_back({"bench --scene " + kSource + "/scenes/bench.yaml --frames -3", "--frames"});
  cases.push_back({"demo --duration abc", "--duration"});
  cases.push_back({"gui --port 70000", "--port"});
  cases.push_back({"emva --size 4", "--size"});
  cases.push_back({"run", "pipeline"});  // the pipeline file is required
  cases.push_back({"explore --seconds abc", "--seconds"});
  cases.push_back({"--log-level loud fk --head " + kHead + " --joints 0 0 0 0", "--log-level"});
  ExpectStatusOne(cases);
}

TEST(ExitStatus, MissingFilesOfEverySubcommandExitOneNamingTheFile) {
  const std::string missing = "/nonexistent/saccade_exit_status.yaml";
  ExpectStatusOne({
      {"fk --head " + missing + " --joints 0 0 0 0", missing},
      {"ik --head " + missing + " --target 1 0 1", missing},
      {"camera --calibration " + missing, missing},
      {"render --frames 1 --scene " + missing, missing},
      {"bench --scene " + missing, missing},
      {"demo --scene " + missing, missing},
      {"gui --scene " + missing, missing},
      {"run " + missing, missing},
      {"urdf --head " + missing, missing},
  });
}

TEST(ExitStatus, AFileWithAWrongEntryExitsOneNamingFileLineAndKey) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("saccade_exit_status_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string scene = (dir / "scene.yaml").string();
  std::ofstream(scene) << "objects:\n  - {name: ball, kind: sphere, radius: -1}\n";
  const std::string pipeline = (dir / "pipeline.yaml").string();
  std::ofstream(pipeline) << "clock: {mode: simulated, step: 0.04, steps: 1}\ncomponents:\n"
                             "  - {name: a, type: no.such_type}\n";
  ExpectStatusOne({
      {"render --frames 1 --force --out " + (dir / "out").string() + " --scene " + scene,
       "scene.yaml:2"},
      {"bench --scene " + scene, "scene.yaml:2"},
      {"gui --scene " + scene, "scene.yaml:2"},
      {"run " + pipeline, "pipeline.yaml:3"},
      {"demo --pipeline " + pipeline, "pipeline.yaml:3"},
  });
  std::filesystem::remove_all(dir);
}

TEST(ExitStatus, NoOrAnUnknownSubcommandExitsOneListingThem) {
  for (const std::string args : {"", "wander", "wander --help", "--log-level debug wander"}) {
    const CommandRun run = Saccade(args);
    EXPECT_EQ(run.status, 1) << "saccade " << args << "\n" << run.output;
    EXPECT_THAT(run.output, HasSubstr("fk, ik, camera, render, bench, demo, gui, run"))
        << "saccade " << args;
  }
  EXPECT_THAT(Saccade("wander").output, HasSubstr("'wander' is not a subcommand"));
  // Alone, one line each: the name and what it does.
  const std::string alone = Saccade("").output;
  EXPECT_THAT(alone, HasSubstr("\n  fk      Forward kinematics\n"));
  EXPECT_THAT(alone, HasSubstr("\n  demo    The main job, the active-vision loop"));
}

TEST(ExitStatus, HelpAndVersionExitZero) {
  for (const std::string args : {"--help", "--version", "fk --help", "render --help",
                                 "bench --help", "gui --help", "--log-level debug run --help"}) {
    const CommandRun run = Saccade(args);
    EXPECT_EQ(run.status, 0) << "saccade " << args << "\n" << run.output;
    EXPECT_THAT(run.output, Not(HasSubstr("saccade: error"))) << "saccade " << args;
  }
}

TEST(ExitStatus, TheServoEmulatorsBadInputExitsOne) {
  for (const std::string args :
       {"--no-such-option", "--ids 1,1", "--positions-deg 400", "--drop-rate x"}) {
    const CommandRun run = saccade::e2e::Run(std::string(SACCADE_SERVO_EMULATOR) + " " + args);
    EXPECT_EQ(run.status, 1) << args << "\n" << run.output;
    EXPECT_THAT(run.output, HasSubstr("saccade-servo-emulator: error: ")) << args;
  }
}

}  // namespace
